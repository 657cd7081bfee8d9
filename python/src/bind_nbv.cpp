// The next-best-view loop over Python objects: a user's camera and arm subclass fvp.Camera
// and fvp.Arm (pybind11 trampolines call their Python methods), the stop condition may be a
// Python predicate, and run_nbv drives them with a session and a planner.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <stdexcept>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/nbv/nbv_loop.h"

namespace fvp::python {
namespace {

using host::nbv::CaptureResult;
using host::nbv::CaptureStatus;
using host::nbv::MoveResult;
using host::nbv::MoveStatus;

/// A Python subclass of fvp.Camera. capture(T) may return a StereoFrame, a CaptureResult
/// (e.g. the simulator camera's), or None for a dropped frame.
class PyCamera : public host::nbv::Camera {
 public:
  CaptureResult capture(const Eigen::Isometry3d& T_world_camera) override {
    py::gil_scoped_acquire gil;
    const py::function method = py::get_override(static_cast<const Camera*>(this), "capture");
    if (!method) throw std::logic_error("fvp.Camera subclass does not define capture(T)");
    const py::object out = method(poseToArray(T_world_camera));
    if (out.is_none()) return {CaptureStatus::kDropped, {}, "the camera returned None"};
    if (py::isinstance<host::StereoFrame>(out))
      return {CaptureStatus::kOk, out.cast<host::StereoFrame>(), {}};
    if (py::isinstance<CaptureResult>(out)) return out.cast<CaptureResult>();
    throw std::invalid_argument(
        "fvp.Camera.capture: expected a StereoFrame, a CaptureResult or None, got " +
        std::string(py::str(py::type::of(out))));
  }
};

MoveResult toMoveResult(const py::object& out) {
  if (py::isinstance<MoveResult>(out)) return out.cast<MoveResult>();
  if (py::isinstance<MoveStatus>(out)) return {out.cast<MoveStatus>(), 0.0};
  if (py::isinstance<py::bool_>(out))
    return {out.cast<bool>() ? MoveStatus::kSuccess : MoveStatus::kExecutionFailed, 0.0};
  throw std::invalid_argument(
      "fvp.Arm.move_to: expected a MoveResult, a MoveStatus or a bool, got " +
      std::string(py::str(py::type::of(out))));
}

/// A Python subclass of fvp.Arm: camera_pose() -> (4, 4), reachable(T) -> bool,
/// move_to(T) -> MoveResult | MoveStatus | bool, and optionally update_obstacles(map) -> int.
class PyArm : public host::nbv::Arm {
 public:
  Eigen::Isometry3d cameraPose() const override {
    py::gil_scoped_acquire gil;
    return poseFromArray(method("camera_pose")(), "fvp.Arm.camera_pose()");
  }
  bool reachable(const Eigen::Isometry3d& T_world_camera) const override {
    py::gil_scoped_acquire gil;
    // None is a forgotten return, not "unreachable".
    return boolFromPython(method("reachable")(poseToArray(T_world_camera)), "fvp.Arm.reachable");
  }
  MoveResult moveTo(const Eigen::Isometry3d& T_world_camera) override {
    py::gil_scoped_acquire gil;
    return toMoveResult(method("move_to")(poseToArray(T_world_camera)));
  }
  std::size_t updateObstacles(host::map::MapEngine& map) override {
    py::gil_scoped_acquire gil;
    const py::function f = py::get_override(static_cast<const Arm*>(this), "update_obstacles");
    if (!f) return 0;
    const py::object out = f(py::cast(&map, py::return_value_policy::reference));
    return out.is_none() ? 0 : out.cast<std::size_t>();
  }

 private:
  py::function method(const char* name) const {
    py::function f = py::get_override(static_cast<const Arm*>(this), name);
    if (!f) throw std::logic_error(std::string("fvp.Arm subclass does not define ") + name);
    return f;
  }
};

/// Observer hooks a Python object may define: on_view(dict), on_plan(dict),
/// on_dropped_frame(str).
class PyObserver : public host::nbv::LoopObserver {
 public:
  explicit PyObserver(py::object target) : target_(std::move(target)) {}
  void onView(const host::nbv::ViewEvent& e) override {
    py::gil_scoped_acquire gil;
    if (!py::hasattr(target_, "on_view")) return;
    py::dict d;
    d["index"] = e.index;
    d["T_world_camera"] = poseToArray(e.T_world_camera);
    d["tag_detected"] = e.result->tag_detected;
    d["roi_points"] = e.result->roi_points;
    d["now_s"] = e.now_s;
    target_.attr("on_view")(d);
  }
  void onPlan(const host::nbv::PlanEvent& e) override {
    py::gil_scoped_acquire gil;
    if (!py::hasattr(target_, "on_plan")) return;
    py::dict d;
    d["iteration"] = e.iteration;
    d["candidates"] = e.step->candidates.size();
    d["moved"] = e.step->moved();
    d["move_attempts"] = e.step->move_attempts;
    d["planning_s"] = e.planning_s;
    d["now_s"] = e.now_s;
    target_.attr("on_plan")(d);
  }
  void onDroppedFrame(const std::string& detail) override {
    py::gil_scoped_acquire gil;
    if (py::hasattr(target_, "on_dropped_frame")) target_.attr("on_dropped_frame")(detail);
  }

 private:
  py::object target_;
};

py::dict nbvResultToDict(const host::nbv::NbvResult& r) {
  py::dict d;
  d["views"] = r.views;
  d["stop_reason"] = r.stop_reason;
  py::list poses;
  for (const auto& T : r.camera_poses) poses.append(poseToArray(T));
  d["camera_poses"] = poses;
  const host::nbv::NbvEvents& e = r.events;
  py::dict events;
  events["planning_iterations"] = e.planning_iterations;
  events["iterations_without_move"] = e.iterations_without_move;
  events["move_attempts"] = e.move_attempts;
  events["failed_moves"] = e.failed_moves;
  events["dropped_frames"] = e.dropped_frames;
  events["views_without_tag"] = e.views_without_tag;
  events["motion_status"] = e.motion_status;
  d["events"] = events;
  const host::nbv::NbvWallTimes& w = r.wall_s;
  py::dict wall;
  wall["capture"] = w.capture;
  wall["perception"] = w.perception;
  wall["mapping"] = w.mapping;
  wall["tsdf"] = w.tsdf;
  wall["planning"] = w.planning;
  wall["motion_planning"] = w.motion_planning;
  wall["moving"] = w.moving;
  d["wall_s"] = wall;
  return d;
}

}  // namespace

void bindNbv(py::module_& m) {
  py::enum_<CaptureStatus>(m, "CaptureStatus")
      .value("ok", CaptureStatus::kOk)
      .value("dropped", CaptureStatus::kDropped);
  py::class_<CaptureResult>(m, "CaptureResult", "A camera's frame, or a dropped frame.")
      .def(py::init([](CaptureStatus status, const py::object& frame, const std::string& detail) {
             CaptureResult r;
             r.status = status;
             if (!frame.is_none()) r.frame = frame.cast<host::StereoFrame>();
             if (r.ok() && frame.is_none())
               throw std::invalid_argument("CaptureResult: status ok needs a frame");
             r.detail = detail;
             return r;
           }),
           py::arg("status"), py::arg("frame") = py::none(), py::arg("detail") = "")
      .def_readonly("status", &CaptureResult::status)
      .def_readonly("frame", &CaptureResult::frame)
      .def_readonly("detail", &CaptureResult::detail)
      .def_property_readonly("ok", &CaptureResult::ok);

  py::enum_<MoveStatus> status(m, "MoveStatus");
  for (const MoveStatus s :
       {MoveStatus::kSuccess, MoveStatus::kNoIk, MoveStatus::kNoCollisionFreeIk,
        MoveStatus::kStartInvalid, MoveStatus::kNoPath, MoveStatus::kTimeout, MoveStatus::kRefused,
        MoveStatus::kExecutionFailed})
    status.value(host::nbv::toString(s), s);
  py::class_<MoveResult>(m, "MoveResult", "How a move ended, and the planning time it took.")
      .def(py::init([](MoveStatus s, double planning_wall_s) {
             return MoveResult{s, planning_wall_s};
           }),
           py::arg("status"), py::arg("planning_wall_s") = 0.0)
      .def_readonly("status", &MoveResult::status)
      .def_readonly("planning_wall_s", &MoveResult::planning_wall_s)
      .def_property_readonly("ok", &MoveResult::ok);

  py::class_<host::nbv::Camera, PyCamera>(
      m, "Camera",
      "Subclass it: capture(T_world_camera) -> StereoFrame | CaptureResult | None (dropped).")
      .def(py::init<>())
      .def(
          "capture",
          [](host::nbv::Camera& c, const py::handle& T) {
            const Eigen::Isometry3d pose = poseFromArray(T, "Camera.capture T_world_camera");
            py::gil_scoped_release release;
            return c.capture(pose);
          },
          py::arg("T_world_camera"));

  py::class_<host::nbv::Arm, PyArm>(
      m, "Arm",
      "Subclass it: camera_pose() -> (4, 4); reachable(T) -> bool; move_to(T) -> MoveResult | "
      "MoveStatus | bool; optionally update_obstacles(map) -> int.")
      .def(py::init<>())
      .def("camera_pose", [](const host::nbv::Arm& a) { return poseToArray(a.cameraPose()); })
      .def(
          "reachable",
          [](const host::nbv::Arm& a, const py::handle& T) {
            return a.reachable(poseFromArray(T, "Arm.reachable T_world_camera"));
          },
          py::arg("T_world_camera"))
      .def(
          "move_to",
          [](host::nbv::Arm& a, const py::handle& T) {
            const Eigen::Isometry3d pose = poseFromArray(T, "Arm.move_to T_world_camera");
            py::gil_scoped_release release;
            return a.moveTo(pose);
          },
          py::arg("T_world_camera"))
      .def(
          "update_obstacles",
          [](host::nbv::Arm& a, host::map::MapEngine& map) { return a.updateObstacles(map); },
          py::arg("map"));

  py::class_<host::nbv::LoopState>(m, "LoopState", "What a stop condition sees.")
      .def(py::init<>(), "An empty state (no views yet): for trying a condition's check().")
      .def_readonly("views", &host::nbv::LoopState::views)
      .def_readonly("iterations", &host::nbv::LoopState::iterations)
      .def_readonly("now_s", &host::nbv::LoopState::now_s)
      .def_readonly("dropped_frames", &host::nbv::LoopState::dropped_frames);

  py::class_<host::nbv::StopCondition>(m, "StopCondition", "When the loop stops; combine with |.")
      .def(py::init([](py::function predicate, std::string reason) {
             // The function is released with the GIL held, whichever thread drops the last
             // copy of the condition.
             std::shared_ptr<py::function> held(new py::function(std::move(predicate)),
                                                [](py::function* f) {
                                                  py::gil_scoped_acquire gil;
                                                  delete f;
                                                });
             return host::nbv::StopCondition(
                 [held](const host::nbv::LoopState& state) {
                   py::gil_scoped_acquire gil;
                   return boolFromPython((*held)(state), "fvp.StopCondition predicate");
                 },
                 std::move(reason));
           }),
           py::arg("predicate"), py::arg("reason"),
           "predicate(LoopState) -> bool; reason names it in the result.")
      .def_static("budget", &host::nbv::StopCondition::budget, py::arg("budget_s"))
      .def_static("views", &host::nbv::StopCondition::views, py::arg("max_views"))
      .def("__or__", &host::nbv::StopCondition::operator||)
      .def("check", &host::nbv::StopCondition::check, py::arg("state"));

  m.def(
      "run_nbv",
      [](Session& session, Planner& planner, host::nbv::Camera& camera, host::nbv::Arm& arm,
         const host::nbv::StopCondition& stop, const py::object& observer,
         int max_consecutive_dropped_frames) {
        host::nbv::SteadyLoopClock clock;
        host::nbv::NbvLoopOptions options;
        options.max_consecutive_dropped_frames = max_consecutive_dropped_frames;
        host::nbv::NbvLoop loop(*session.session, *planner.planner, camera, arm, clock, options);
        std::optional<PyObserver> hooks;
        if (!observer.is_none()) hooks.emplace(observer);
        host::nbv::NbvResult result;
        {
          py::gil_scoped_release release;
          const std::scoped_lock lock(session.mutex, planner.mutex);
          result = loop.run(stop, hooks ? &*hooks : nullptr);
        }
        return nbvResultToDict(result);
      },
      py::arg("session"), py::arg("planner"), py::arg("camera"), py::arg("arm"), py::arg("stop"),
      py::arg("observer") = py::none(), py::arg("max_consecutive_dropped_frames") = 10,
      "The next-best-view loop on the wall clock: capture at the arm's pose, perceive and map, "
      "plan, move, until stop holds. Returns views, stop_reason, camera_poses, events, wall_s.");
}

}  // namespace fvp::python
