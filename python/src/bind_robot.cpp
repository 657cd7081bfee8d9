// The robot from Python: a user's camera and arm subclass fvp.Camera and fvp.Arm (pybind11
// trampolines call their Python methods); what a capture and a move return.
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/nbv/arm.h"
#include "fvp/host/nbv/camera.h"

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
    return {out.cast<bool>() ? MoveStatus::kSuccess : MoveStatus::kExecutionFailed, 0.0, 0.0};
  throw std::invalid_argument(
      "fvp.Arm.move_to: expected a MoveResult, a MoveStatus or a bool, got " +
      std::string(py::str(py::type::of(out))));
}

/// A Python subclass of fvp.Arm: camera_pose() -> (4, 4), reachable(T) -> bool,
/// move_to(T) -> MoveResult | MoveStatus | bool, and optionally update_obstacles(map) -> int
/// and check_goal(T) -> GoalReach | GoalCheck (the loop then checks ranked views with it
/// before moving, and tries a batch by information per second where travel_s is given) and
/// travel_time_s(T_from, T_to) -> float (a tour orders its clusters by it; NaN: unknown).
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
  bool checksGoals() const override {
    py::gil_scoped_acquire gil;
    return static_cast<bool>(py::get_override(static_cast<const Arm*>(this), "check_goal"));
  }
  host::planner::GoalReach checkGoal(const Eigen::Isometry3d& T_world_camera) const override {
    py::gil_scoped_acquire gil;
    const py::object out = method("check_goal")(poseToArray(T_world_camera));
    if (py::isinstance<host::planner::GoalReach>(out)) return out.cast<host::planner::GoalReach>();
    if (py::isinstance<host::planner::GoalCheck>(out))  // no travel time: ranked as planned
      return {out.cast<host::planner::GoalCheck>()};
    throw std::invalid_argument("fvp.Arm.check_goal: expected a GoalReach or a GoalCheck, got " +
                                std::string(py::str(py::type::of(out))));
  }
  double travelTime_s(const Eigen::Isometry3d& T_world_from_camera,
                      const Eigen::Isometry3d& T_world_to_camera) const override {
    py::gil_scoped_acquire gil;
    const py::function f = py::get_override(static_cast<const Arm*>(this), "travel_time_s");
    if (!f) return Arm::travelTime_s(T_world_from_camera, T_world_to_camera);
    const py::object out = f(poseToArray(T_world_from_camera), poseToArray(T_world_to_camera));
    if (py::isinstance<py::bool_>(out) ||
        (!py::isinstance<py::float_>(out) && !py::isinstance<py::int_>(out)))
      throw std::invalid_argument("fvp.Arm.travel_time_s: expected a number, got " +
                                  std::string(py::str(py::type::of(out))));
    const double seconds = out.cast<double>();
    if (seconds < 0.0)  // NaN: unknown, allowed
      throw std::invalid_argument("fvp.Arm.travel_time_s: expected seconds >= 0 or nan, got " +
                                  std::to_string(seconds));
    return seconds;
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

/// fvp.MoveStatus and fvp.MoveResult: how a move ended.
void bindMoveResult(py::module_& m) {
  py::enum_<MoveStatus> status(m, "MoveStatus");
  for (const MoveStatus s :
       {MoveStatus::kSuccess, MoveStatus::kNoIk, MoveStatus::kNoCollisionFreeIk,
        MoveStatus::kStartInvalid, MoveStatus::kNoPath, MoveStatus::kTimeout, MoveStatus::kRefused,
        MoveStatus::kExecutionFailed})
    status.value(host::nbv::toString(s), s);
  py::class_<MoveResult>(m, "MoveResult",
                         "How a move ended, the planning time it took and the arm's time in "
                         "motion.")
      .def(py::init([](MoveStatus s, double planning_wall_s, double motion_s, bool retreated) {
             if (!(motion_s >= 0.0) || !std::isfinite(motion_s))
               throw py::value_error("fvp.MoveResult: motion_s: expected seconds >= 0");
             return MoveResult{s, planning_wall_s, motion_s, retreated};
           }),
           py::arg("status"), py::arg("planning_wall_s") = 0.0, py::arg("motion_s") = 0.0,
           py::arg("retreated") = false)
      .def_readonly("status", &MoveResult::status)
      .def_readonly("planning_wall_s", &MoveResult::planning_wall_s)
      .def_readonly("motion_s", &MoveResult::motion_s)
      .def_readonly("retreated", &MoveResult::retreated)
      .def_property_readonly("ok", &MoveResult::ok);
}

}  // namespace

void bindRobot(py::module_& m) {
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

  bindMoveResult(m);

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

  py::enum_<host::planner::GoalCheck> goal_check(
      m, "GoalCheck", "Whether the arm has a collision-free IK solution for a camera pose.");
  for (const host::planner::GoalCheck g :
       {host::planner::GoalCheck::kFeasible, host::planner::GoalCheck::kNoIk,
        host::planner::GoalCheck::kNoCollisionFreeIk})
    goal_check.value(host::planner::toString(g), g);
  py::class_<host::planner::GoalReach>(
      m, "GoalReach",
      "A goal check's answer: check (GoalCheck) and, when feasible, travel_s: the least the "
      "move takes (the straight motion to the goal configuration, at the joints' limits); NaN "
      "when unknown. The loop tries a checked batch by information per second with it.")
      .def(py::init([](host::planner::GoalCheck check, double travel_s) {
             return host::planner::GoalReach{check, travel_s};
           }),
           py::arg("check"), py::arg("travel_s") = std::numeric_limits<double>::quiet_NaN())
      .def_readonly("check", &host::planner::GoalReach::check)
      .def_readonly("travel_s", &host::planner::GoalReach::travel_s)
      .def("__repr__", [](const host::planner::GoalReach& r) {
        return std::string("GoalReach(") + host::planner::toString(r.check) +
               ", travel_s=" + std::to_string(r.travel_s) + ")";
      });

  py::class_<host::nbv::Arm, PyArm>(
      m, "Arm",
      "Subclass it: camera_pose() -> (4, 4); reachable(T) -> bool; move_to(T) -> MoveResult | "
      "MoveStatus | bool; optionally update_obstacles(map) -> int and check_goal(T) -> "
      "GoalReach | GoalCheck (IK and collision only: ranked views it turns down are not moved "
      "to; a GoalReach's travel_s orders each checked batch by information per second) and "
      "travel_time_s(T_from, T_to) -> float (a tour visits its clusters in the least time by "
      "it; NaN or absent: by camera distance).")
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
          py::arg("map"))
      .def(
          "check_goal",
          [](const host::nbv::Arm& a, const py::handle& T) {
            const Eigen::Isometry3d pose = poseFromArray(T, "Arm.check_goal T_world_camera");
            py::gil_scoped_release release;
            return a.checkGoal(pose);
          },
          py::arg("T_world_camera"))
      .def(
          "travel_time_s",
          [](const host::nbv::Arm& a, const py::handle& T_from, const py::handle& T_to) {
            const Eigen::Isometry3d from = poseFromArray(T_from, "Arm.travel_time_s T_from");
            const Eigen::Isometry3d to = poseFromArray(T_to, "Arm.travel_time_s T_to");
            py::gil_scoped_release release;
            return a.travelTime_s(from, to);
          },
          py::arg("T_world_from_camera"), py::arg("T_world_to_camera"))
      .def_property_readonly("checks_goals", &host::nbv::Arm::checksGoals);
}

}  // namespace fvp::python
