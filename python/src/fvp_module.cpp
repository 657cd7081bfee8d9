// The fvp Python module (docs/python.md): frames from numpy, the mapping session, planners
// by name, batch information gain, capture-set sizing; bind_nbv.cpp adds the loop over
// Python cameras and arms, bind_sim.cpp the simulator's trials.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <filesystem>
#include <stdexcept>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/core/input_checks.h"
#include "fvp/host/eval/sizing_score.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/planner/info_gain_evaluator.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/host/session/capture_sizing.h"

namespace fvp::python {

std::unique_ptr<accel::Backend> backendFor(const std::string& name, const std::string& engine) {
  if (name == "none") {
    if (host::map::mapEngineNeedsBackend(engine))
      throw std::invalid_argument("backend 'none': map engine '" + engine +
                                  "' needs a compute backend");
    return nullptr;
  }
  return host::map::createBackendFor(engine, name);
}

namespace {
/// "none" (the planner's kernels on the host), else the named backend.
std::unique_ptr<accel::Backend> backendOrNone(const std::string& name) {
  return name == "none" ? nullptr : accel::createBackend(name);
}
}  // namespace

Session::Session(const host::PerceptionConfig& perception, const std::string& engine_name,
                 const std::string& backend_name, const std::string& planner, bool tsdf,
                 bool register_views)
    : backend(backendFor(backend_name, engine_name)), engine(engine_name) {
  session = std::make_unique<host::MappingSession>(
      perception, engine, host::planner::plannerMapConfig(planner, engine), backend.get());
  if (tsdf) session->enableTsdf();
  if (register_views) session->enableViewRegistration();
}

Planner::Planner(const std::string& name, const std::string& config_yaml, std::uint64_t seed,
                 const std::string& backend_name)
    : backend(backendOrNone(backend_name)) {
  planner = host::planner::createPlanner(name, config_yaml, seed, backend.get());
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

host::map::MapEngine& requireMap(Session& s, const char* what) {
  if (!s.session->map())
    throw std::runtime_error(std::string(what) +
                             ": no map yet (no view showed the tag and no region_center_m is "
                             "configured)");
  return *s.session->map();
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

}  // namespace fvp::python

PYBIND11_MODULE(fvp, m) {
  using namespace fvp;
  using namespace fvp::python;
  m.doc() = "fvp: fruitlet sizing with next-best-view planning (docs/python.md)";

  m.def(
      "planners", [] { return host::planner::PlannerRegistry::instance().names(); },
      "The registered viewpoint planners' names.");
  m.def(
      "map_engines", [] { return host::map::MapEngineRegistry::instance().names(); },
      "The registered map engines' names.");
  m.def(
      "backends",
      [] {
        py::dict out;
        for (const auto& info : accel::probeBackends())
          out[py::str(std::string(accel::toString(info.kind)))] =
              info.available ? std::string("available") : info.reason;
        return out;
      },
      "Every compute backend built in: 'available', or why it cannot run here.");

  py::class_<host::StereoIntrinsics>(m, "StereoIntrinsics",
                                     "Rectified stereo pair: pixels, focal lengths, baseline.")
      .def(py::init([](int width_px, int height_px, double fx_px, double fy_px, double cx_px,
                       double cy_px, double baseline_m) {
             host::StereoIntrinsics k;
             k.width_px = width_px;
             k.height_px = height_px;
             k.fx_px = fx_px;
             k.fy_px = fy_px;
             k.cx_px = cx_px;
             k.cy_px = cy_px;
             k.baseline_m = baseline_m;
             host::checkIntrinsics(k, "StereoIntrinsics");
             return k;
           }),
           py::kw_only(), py::arg("width_px"), py::arg("height_px"), py::arg("fx_px"),
           py::arg("fy_px"), py::arg("cx_px"), py::arg("cy_px"), py::arg("baseline_m"))
      .def_readonly("width_px", &host::StereoIntrinsics::width_px)
      .def_readonly("height_px", &host::StereoIntrinsics::height_px)
      .def_readonly("fx_px", &host::StereoIntrinsics::fx_px)
      .def_readonly("fy_px", &host::StereoIntrinsics::fy_px)
      .def_readonly("cx_px", &host::StereoIntrinsics::cx_px)
      .def_readonly("cy_px", &host::StereoIntrinsics::cy_px)
      .def_readonly("baseline_m", &host::StereoIntrinsics::baseline_m);

  py::class_<host::StereoFrame>(m, "StereoFrame",
                                "One rectified stereo view with its pose; optionally the "
                                "robot's own fruitlet mask and disparity, used as given. A "
                                "uint16 fruitlet_mask is an instance segmentation (0 = "
                                "background, each id one fruitlet); any other is a binary "
                                "mask (nonzero = fruitlet).")
      .def(py::init([](const py::handle& left, const py::handle& right,
                       const host::StereoIntrinsics& intrinsics, const py::handle& T_world_camera,
                       const py::handle& fruitlet_mask, const py::handle& disparity_px) {
             host::StereoFrame f;
             f.left_bgr = bgrFromArray(left, "StereoFrame left");
             f.right_bgr = bgrFromArray(right, "StereoFrame right");
             f.intrinsics = intrinsics;
             f.T_world_camera = poseFromArray(T_world_camera, "StereoFrame T_world_camera");
             if (!fruitlet_mask.is_none())
               f.fruitlet_mask = maskFromArray(fruitlet_mask, "StereoFrame fruitlet_mask");
             if (!disparity_px.is_none())
               f.disparity_px = floatImageFromArray(disparity_px, "StereoFrame disparity_px");
             host::checkStereoFrame(f, "StereoFrame");
             return f;
           }),
           py::arg("left"), py::arg("right"), py::arg("intrinsics"), py::arg("T_world_camera"),
           py::arg("fruitlet_mask") = py::none(), py::arg("disparity_px") = py::none())
      .def_property_readonly("left",
                             [](const host::StereoFrame& f) { return imageToArray(f.left_bgr); })
      .def_property_readonly("right",
                             [](const host::StereoFrame& f) { return imageToArray(f.right_bgr); })
      .def_property_readonly(
          "fruitlet_mask", [](const host::StereoFrame& f) { return imageToArray(f.fruitlet_mask); })
      .def_property_readonly(
          "disparity_px", [](const host::StereoFrame& f) { return imageToArray(f.disparity_px); })
      .def_readonly("intrinsics", &host::StereoFrame::intrinsics)
      .def_property_readonly("T_world_camera", [](const host::StereoFrame& f) {
        return poseToArray(f.T_world_camera);
      });

  py::class_<host::PerceptionConfig>(m, "PerceptionConfig",
                                     "The tag, the Cluster Region (from the tag or explicit) "
                                     "and the HSV thresholds (docs/capture-format.md).")
      .def(py::init<>())
      .def_static(
          "from_yaml",
          [](const std::string& path) { return host::PerceptionConfig::fromYamlFile(path); },
          py::arg("path"));

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
              step = p.planner->planAndMove(
                  map, T,
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

  bindNbv(m);
  bindSim(m);
}
