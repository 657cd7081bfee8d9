// Perception and sizing from Python: the perception configuration (tag, Cluster Region, HSV
// thresholds), `fvp size` over a capture set, and `fvp season` over visits' results.
#include <pybind11/stl.h>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/report/capture_set_report.h"
#include "fvp/host/season/season_analysis.h"

namespace fvp::python {

void bindPerceptionSizing(py::module_& m) {
  py::class_<host::PerceptionConfig>(m, "PerceptionConfig",
                                     "The tag, the Cluster Region (from the tag or explicit) "
                                     "and the HSV thresholds (docs/capture-format.md).")
      .def(py::init<>())
      .def_static(
          "from_yaml",
          [](const std::string& path) { return host::PerceptionConfig::fromYamlFile(path); },
          py::arg("path"));

  m.def(
      "size_captures",
      [](const std::string& captures_dir, const std::string& config, const std::string& out_dir,
         const std::string& estimator, const std::string& engine, const std::string& backend_name) {
        host::CaptureSizingOptions options;
        if (!config.empty()) options.perception = host::PerceptionConfig::fromYamlFile(config);
        options.estimator = host::sizing::parseSizingEstimator(estimator);
        options.engine = engine;
        options.out_dir = out_dir;
        const std::unique_ptr<accel::Backend> backend = backendFor(backend_name, engine);
        nlohmann::json result;
        {
          py::gil_scoped_release release;
          result = host::sizeCaptureSet(captures_dir, options, backend.get());
        }
        return jsonToPython(result);
      },
      py::arg("captures_dir"), py::arg("config") = "", py::arg("out_dir") = "",
      py::arg("estimator") = "ours", py::arg("engine") = "grid", py::arg("backend") = "auto",
      "`fvp size` as a function: sizes a capture set (docs/capture-format.md) and returns "
      "fruitlets.json's object (written to out_dir when given).");

  m.def(
      "season",
      [](const std::vector<std::pair<double, std::string>>& visits, double size_error_floor_mm) {
        std::vector<host::season::SeasonVisit> read;
        for (const auto& [day, path] : visits)
          read.push_back(host::season::readSeasonVisit(path, day));
        host::season::SeasonConfig config;
        config.size_error_floor_mm = size_error_floor_mm;
        return jsonToPython(
            host::season::seasonJson(host::season::analyzeSeason(read, config), config));
      },
      py::arg("visits"),
      py::arg("size_error_floor_mm") = host::season::SeasonConfig{}.size_error_floor_mm,
      "`fvp season` as a function: visits as (day, path) pairs, each path a result.json, a "
      "fruitlets.json or a directory holding one, and the floor added in quadrature to each "
      "size's standard error; returns season.json's object (docs/season.md).");
}

}  // namespace fvp::python
