// fvp.MappingSession: views through perception into the maps and the TSDF, sizing on demand;
// fvp.MapEngine, the maps it holds.
#include <pybind11/stl.h>

#include <stdexcept>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/eval/sizing_score.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/planner/planner_registry.h"

namespace fvp::python {

Session::Session(const host::PerceptionConfig& perception, const std::string& engine_name,
                 const std::string& backend_name, const std::string& planner, bool tsdf,
                 bool register_views)
    : backend(backendFor(backend_name, engine_name)), engine(engine_name) {
  session = std::make_unique<host::MappingSession>(
      perception, engine, host::planner::plannerMapConfig(planner, engine), backend.get());
  if (tsdf) session->enableTsdf();
  if (register_views) session->enableViewRegistration();
}

host::map::MapEngine& requireMap(Session& s, const char* what) {
  if (!s.session->map())
    throw std::runtime_error(std::string(what) +
                             ": no map yet (no view showed the tag and no region_center_m is "
                             "configured)");
  return *s.session->map();
}

namespace {

py::dict viewResultToDict(const host::ViewResult& v) {
  py::dict d;
  d["index"] = v.index;
  d["tag_detected"] = v.tag_detected;
  d["roi_points"] = v.roi_points;
  d["other_points"] = v.other_points;
  d["integrated"] = v.integrated;
  d["earlier_views_integrated"] = v.earlier_views_integrated;
  d["perceive_s"] = v.perceive_s;
  d["mapping_s"] = v.scan.seconds;
  d["tsdf_s"] = v.tsdf_s;
  return d;
}

}  // namespace

void bindSession(py::module_& m) {
  py::class_<host::map::MapEngine>(m, "MapEngine",
                                   "The session's maps (handed to Arm.update_obstacles).")
      .def_property_readonly(
          "engine", [](const host::map::MapEngine& e) { return std::string(e.engineName()); })
      .def_property_readonly("scans", &host::map::MapEngine::scanCount);

  py::class_<Session>(m, "MappingSession",
                      "Views through perception into the maps and the TSDF; sizing on demand.")
      .def(py::init([](const py::object& perception, const std::string& engine,
                       const std::string& backend, const std::string& planner, bool tsdf,
                       bool register_views) {
             const host::PerceptionConfig config = perception.is_none()
                                                       ? host::PerceptionConfig{}
                                                       : perception.cast<host::PerceptionConfig>();
             return std::make_unique<Session>(config, engine, backend, planner, tsdf,
                                              register_views);
           }),
           py::arg("perception") = py::none(), py::arg("engine") = "grid",
           py::arg("backend") = "auto", py::arg("planner") = "fvp", py::arg("tsdf") = true,
           py::arg("register_views") = false,
           "register_views: align each view to the earlier ones before fusing it and report "
           "sizes corrected by the registered map's estimated offset (docs/sizing.md).")
      .def(
          "add_view",
          [](Session& s, const host::StereoFrame& frame) {
            host::ViewResult v;
            {
              py::gil_scoped_release release;
              const std::lock_guard lock(s.mutex);
              v = s.session->addView(frame);
            }
            return viewResultToDict(v);
          },
          py::arg("frame"), "Perceives a frame and integrates it; returns what the view did.")
      .def_property_readonly("views",
                             [](const Session& s) {
                               py::gil_scoped_release release;
                               const std::lock_guard lock(s.mutex);
                               return s.session->views().size();
                             })
      .def_property_readonly("region",
                             [](const Session& s) -> py::object {
                               std::optional<host::ClusterRegion> region;
                               {
                                 py::gil_scoped_release release;
                                 const std::lock_guard lock(s.mutex);
                                 region = s.session->region();
                               }
                               if (!region) return py::none();
                               py::dict d;
                               d["center_m"] = vectorToArray(region->center_m());
                               d["radius_m"] = region->radius_m();
                               return d;
                             })
      .def_property_readonly(
          "map", [](Session& s) -> host::map::MapEngine* { return s.session->map(); },
          py::return_value_policy::reference_internal)
      .def_property_readonly(
          "anchor_offset",
          [](const Session& s) {
            host::AnchorOffset offset;
            bool applied = false;
            {
              py::gil_scoped_release release;
              const std::lock_guard lock(s.mutex);
              offset = s.session->anchorOffset();
              applied = s.session->correctsAnchorOffset();
            }
            py::dict d;
            d["shift_m"] = vectorToArray(offset.shift_m);
            d["hand_eye_m"] = vectorToArray(offset.hand_eye_m);
            d["views"] = offset.views;
            d["valid"] = offset.valid;
            d["applied"] = applied && offset.valid;
            return d;
          },
          "With register_views: the registered map's estimated offset from the world at the "
          "cluster (shift_m, added to reported positions when applied), its hand-eye term and "
          "the views it rests on, whether valid; zeros without registration.")
      .def(
          "surface_points",
          [](const Session& s) {
            std::vector<Eigen::Vector3f> points;
            {
              py::gil_scoped_release release;
              const std::lock_guard lock(s.mutex);
              points = s.session->surfacePoints();
            }
            return pointsToArray(points);
          },
          "The TSDF's surface points, (N, 3) float32, metres.")
      .def(
          "size_fruitlets",
          [](const Session& s, const std::string& estimator) {
            host::sizing::SizingConfig config;
            config.estimator = host::sizing::parseSizingEstimator(estimator);
            host::sizing::SizingResult sized;
            {
              py::gil_scoped_release release;
              const std::lock_guard lock(s.mutex);
              sized = s.session->sizeFruitlets(config);
            }
            py::dict out = jsonToPython(host::eval::sizingDetails(sized));
            out["points"] = pointsToArray(sized.points);
            out["labels"] = py::array_t<int>(py::ssize_t(sized.labels.size()), sized.labels.data());
            return out;
          },
          py::arg("estimator") = "ours",
          "Sizes the fruitlets: the sizing details (sized_fruitlets with centres, sizes, "
          "per-image sizes), the filtered surface points (N, 3) and their DBSCAN labels (N,).");
}

}  // namespace fvp::python
