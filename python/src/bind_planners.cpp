// The planners from Python: fvp.Planner (a registered planner's next best view on a
// session's maps) and info_gain (paper Eq. 1-2 of a batch of poses).
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <stdexcept>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/planner/info_gain_evaluator.h"
#include "fvp/host/planner/planner_registry.h"

namespace fvp::python {
namespace {

/// "none" (the planner's kernels on the host), else the named backend.
std::unique_ptr<accel::Backend> backendOrNone(const std::string& name) {
  return name == "none" ? nullptr : accel::createBackend(name);
}

py::dict candidatesToDict(const std::vector<host::planner::Candidate>& candidates) {
  const py::ssize_t n = py::ssize_t(candidates.size());
  py::array_t<double> poses({n, py::ssize_t(4), py::ssize_t(4)}), targets({n, py::ssize_t(3)}),
      ig(n), utility(n);
  py::array_t<bool> reachable(n);
  py::list kinds;
  auto p = poses.mutable_unchecked<3>();
  auto t = targets.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& c = candidates[std::size_t(i)];
    for (int r = 0; r < 4; ++r)
      for (int k = 0; k < 4; ++k) p(i, r, k) = c.T_world_camera.matrix()(r, k);
    for (int k = 0; k < 3; ++k) t(i, k) = c.target_m[k];
    ig.mutable_at(i) = c.ig;
    utility.mutable_at(i) = c.utility;
    reachable.mutable_at(i) = c.reachable;
    kinds.append(host::planner::toString(c.kind));
  }
  py::dict d;
  d["T_world_camera"] = poses;
  d["target_m"] = targets;
  d["ig"] = ig;
  d["utility"] = utility;
  d["reachable"] = reachable;
  d["kind"] = kinds;
  return d;
}

}  // namespace

Planner::Planner(const std::string& name, const std::string& config_yaml, std::uint64_t seed,
                 const std::string& backend_name)
    : backend(backendOrNone(backend_name)) {
  planner = host::planner::createPlanner(name, config_yaml, seed, backend.get());
}

void bindPlanners(py::module_& m) {
  py::class_<Planner>(m, "Planner", "A registered viewpoint planner (fvp.planners()).")
      .def(py::init<const std::string&, const std::string&, std::uint64_t, const std::string&>(),
           py::arg("name") = "fvp", py::arg("config") = "", py::arg("seed") = 1,
           py::arg("backend") = "auto")
      .def_property_readonly("name",
                             [](const Planner& p) { return std::string(p.planner->name()); })
      .def_property_readonly("config",
                             [](const Planner& p) {
                               return jsonToPython(nlohmann::json::parse(p.planner->configJson()));
                             })
      .def(
          "next_best_view",
          [](Planner& p, Session& s, const py::handle& T_now, const py::object& reachable) {
            const Eigen::Isometry3d T = poseFromArray(T_now, "next_best_view T_world_camera");
            std::optional<Eigen::Isometry3d> chosen;
            host::planner::PlanStep step;
            {
              py::gil_scoped_release release;
              const std::scoped_lock lock(p.mutex, s.mutex);
              host::map::MapEngine& map = requireMap(s, "next_best_view");
              // The robot makes the move: the best candidate is taken.
              step = host::planner::planAndMove(
                  *p.planner, map, T,
                  [&](const Eigen::Isometry3d& pose) {
                    if (reachable.is_none()) return true;
                    py::gil_scoped_acquire gil;
                    return boolFromPython(reachable(poseToArray(pose)), "next_best_view reachable");
                  },
                  [&](const Eigen::Isometry3d& pose) {
                    chosen = pose;
                    return true;
                  });
            }
            py::dict d;
            d["T_world_camera"] = chosen ? py::object(poseToArray(*chosen)) : py::none();
            d["chosen"] = step.chosen ? py::object(py::int_(*step.chosen)) : py::none();
            d["candidates"] = candidatesToDict(step.candidates);
            py::dict timings;
            for (const auto& [stage, seconds] : step.timings_s) timings[stage.c_str()] = seconds;
            d["timings_s"] = timings;
            return d;
          },
          py::arg("session"), py::arg("T_world_camera"), py::arg("reachable") = py::none(),
          "One planning iteration on the session's maps from the camera pose: the best "
          "candidate's pose (None when none is worth a view), its index and every candidate "
          "scored. reachable(T) -> bool filters candidates (default: all reachable).");

  m.def(
      "info_gain",
      [](Session& s, const py::handle& poses, const py::handle& targets, const std::string& mode,
         double max_d_m, const std::string& backend_name) {
        auto P = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(poses);
        auto X = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(targets);
        if (!P || P.ndim() != 3 || P.shape(1) != 4 || P.shape(2) != 4)
          throw std::invalid_argument("info_gain: poses: expected shape (N, 4, 4)");
        if (!X || X.ndim() != 2 || X.shape(0) != P.shape(0) || X.shape(1) != 3)
          throw std::invalid_argument("info_gain: targets: expected shape (N, 3), N as poses");
        std::vector<host::planner::ViewQuery> queries(std::size_t(P.shape(0)));
        for (py::ssize_t i = 0; i < P.shape(0); ++i) {
          queries[std::size_t(i)].T_world_camera =
              poseFromArray(py::array_t<double>({4, 4}, P.data(i, 0, 0)),
                            "info_gain poses[" + std::to_string(i) + "]");
          queries[std::size_t(i)].target_m = vectorFromArray(
              py::array_t<double>(3, X.data(i, 0)), "info_gain targets[" + std::to_string(i) + "]");
        }
        host::planner::InfoGainConfig config;
        config.mode = host::planner::parseGainMode(mode);
        config.max_d_m = max_d_m;
        config.validate();
        const std::unique_ptr<accel::Backend> backend = backendOrNone(backend_name);
        std::vector<host::planner::GainResult> gains;
        {
          py::gil_scoped_release release;
          const std::lock_guard lock(s.mutex);
          host::map::MapEngine& map = requireMap(s, "info_gain");
          host::planner::InfoGainEvaluator evaluator(config, backend.get());
          evaluator.refresh(map);
          gains = evaluator.evaluate(queries);
        }
        py::array_t<double> ig(py::ssize_t(gains.size()));
        for (std::size_t i = 0; i < gains.size(); ++i) ig.mutable_at(py::ssize_t(i)) = gains[i].ig;
        return ig;
      },
      py::arg("session"), py::arg("poses"), py::arg("targets"), py::arg("mode") = "single_ray",
      py::arg("max_d_m") = 0.02, py::arg("backend") = "auto",
      "Information gain (paper Eq. 1-2) of N camera poses (N, 4, 4) looking at targets "
      "(N, 3) on the session's maps, in one batch: an (N,) array.");
}

}  // namespace fvp::python
