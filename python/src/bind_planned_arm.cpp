// The real-robot arm from Python: fvp.PlannedArm (robot::PlannedArm: fvp's reachability and
// IK + OMPL planning) over a Python driver: a joint-state source and a trajectory executor,
// each an fvp.JointStateSource / fvp.TrajectoryExecutor subclass or a plain callable. The
// arm model (fvp.ArmModel, the arm YAML of fvp run --arm) and its workspace tree
// (fvp.WorkspaceTree) come with it.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "bindings.h"
#include "conversions.h"
#include "fvp/robot/ik_reachability.h"
#include "fvp/robot/planned_arm.h"
#include "fvp/robot/workspace_tree.h"

namespace fvp::python {
namespace {

using robot::ExecutionResult;
using robot::ExecutionStatus;
using robot::JointVector;

/// A (7,) array or sequence of finite numbers -> joints; `what` names it in the error.
JointVector jointsFromPython(const py::handle& object, const std::string& what) {
  if (object.is_none()) throw std::invalid_argument(what + ": expected 7 joints, got None");
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!array || array.ndim() != 1 || array.shape(0) != robot::kArmJoints) {
    throw std::invalid_argument(what + ": expected 7 joints (slider m, 6 UR5 rad), got " +
                                std::string(py::str(py::repr(object))));
  }
  JointVector q;
  for (int j = 0; j < robot::kArmJoints; ++j) q[j] = array.at(j);
  if (!q.allFinite()) throw std::invalid_argument(what + ": expected finite joints");
  return q;
}

py::array_t<double> jointsToArray(const JointVector& q) {
  py::array_t<double> out(robot::kArmJoints);
  for (int j = 0; j < robot::kArmJoints; ++j) out.mutable_at(j) = q[j];
  return out;
}

ExecutionResult executionFromPython(const py::handle& out) {
  if (py::isinstance<ExecutionResult>(out)) return out.cast<ExecutionResult>();
  if (py::isinstance<ExecutionStatus>(out)) return {out.cast<ExecutionStatus>(), {}};
  if (py::isinstance<py::bool_>(out))
    return {out.cast<bool>() ? ExecutionStatus::kDone : ExecutionStatus::kFailed, {}};
  // None is a forgotten return, not a failure.
  throw std::invalid_argument(
      "fvp.TrajectoryExecutor.execute: expected an ExecutionStatus, an ExecutionResult or a "
      "bool, got " +
      std::string(py::str(py::type::of(out))));
}

/// What to call: a subclass's method, or the object itself when it is a plain callable.
py::object driverCallable(const py::object& object, const py::handle& base, const char* method,
                          const char* what) {
  py::object f = py::isinstance(object, base) ? object.attr(method) : object;
  if (!PyCallable_Check(f.ptr()))
    throw std::invalid_argument(std::string("fvp.PlannedArm: ") + what + " must be an fvp." +
                                std::string(py::str(base.attr("__name__"))) +
                                " subclass or a callable");
  return f;
}

/// The Python joint-state source behind robot::JointStateSource.
class PythonJointState : public robot::JointStateSource {
 public:
  explicit PythonJointState(py::object f) : f_(std::move(f)) {}
  JointVector jointPositions() const override {
    py::gil_scoped_acquire gil;
    return jointsFromPython(f_(), "fvp.JointStateSource.joint_positions()");
  }

 private:
  py::object f_;
};

/// The Python executor behind robot::TrajectoryExecutor: the trajectory as time points
/// (sampleTimes_s) and the joints at each.
class PythonExecutor : public robot::TrajectoryExecutor {
 public:
  PythonExecutor(py::object f, double sample_period_s)
      : f_(std::move(f)), period_s_(sample_period_s) {
    if (!(sample_period_s > 0.0) || !std::isfinite(sample_period_s))
      throw std::invalid_argument("fvp.PlannedArm: sample_period_s must be positive and finite");
  }
  ExecutionResult execute(const robot::Trajectory& trajectory) override {
    const std::vector<double> times_s = robot::sampleTimes_s(trajectory, period_s_);
    py::gil_scoped_acquire gil;
    const auto n = static_cast<py::ssize_t>(times_s.size());
    py::array_t<double> times(n), positions({n, static_cast<py::ssize_t>(robot::kArmJoints)});
    auto t = times.mutable_unchecked<1>();
    auto q = positions.mutable_unchecked<2>();
    for (py::ssize_t i = 0; i < n; ++i) {
      t(i) = times_s[static_cast<std::size_t>(i)];
      const JointVector qi = trajectory.position(t(i));
      for (int j = 0; j < robot::kArmJoints; ++j) q(i, j) = qi[j];
    }
    return executionFromPython(f_(times, positions));
  }

 private:
  py::object f_;
  double period_s_;
};

/// What PlannedArm refers to, built before it (a base listed first is constructed first).
struct PlannedArmParts {
  PlannedArmParts(const robot::ArmModel& model, const py::object& workspace,
                  PythonJointState joint_state, PythonExecutor executor)
      : ik(workspace.is_none() ? std::make_unique<robot::IkReachability>(model) : nullptr),
        reachability(ik ? static_cast<const robot::Reachability&>(*ik)
                        : workspace.cast<const robot::WorkspaceTree&>()),
        joint_state(std::move(joint_state)),
        executor(std::move(executor)) {}
  std::unique_ptr<robot::IkReachability> ik;
  const robot::Reachability& reachability;
  PythonJointState joint_state;
  PythonExecutor executor;
};

class PyPlannedArm : private PlannedArmParts, public robot::PlannedArm {
 public:
  PyPlannedArm(const robot::ArmModel& model, const py::object& workspace,
               PythonJointState joint_state, PythonExecutor executor, double goal_tolerance)
      : PlannedArmParts(model, workspace, std::move(joint_state), std::move(executor)),
        robot::PlannedArm(model, reachability, PlannedArmParts::joint_state,
                          PlannedArmParts::executor, goal_tolerance) {}
};

/// A move for the log: the loop's status, the planner's, the driver's answer.
py::dict moveToDict(const robot::PlannedMove& move) {
  py::dict out;
  out["status"] = py::cast(move.status);
  out["planning_wall_s"] = move.plan.planning_wall_s;
  out["motion_status"] = robot::toString(move.plan.status);
  out["duration_s"] = move.plan.ok() ? move.plan.trajectory.duration_s() : 0.0;
  out["retreated"] = move.result().retreated;
  out["execution"] = move.plan.ok() ? py::cast(move.execution.status) : py::none();
  out["detail"] = move.execution.detail;
  return out;
}

// Python-side bases only (documentation and a clear error for a missing method): PlannedArm
// calls the subclass's method through driverCallable.
struct ExecutorBase {};
struct JointStateBase {};

void bindDriverInterfaces(py::module_& m) {
  py::enum_<ExecutionStatus>(m, "ExecutionStatus")
      .value("done", ExecutionStatus::kDone)
      .value("refused", ExecutionStatus::kRefused)
      .value("failed", ExecutionStatus::kFailed);
  py::class_<ExecutionResult>(m, "ExecutionResult", "How a trajectory's execution ended.")
      .def(py::init([](ExecutionStatus s, const std::string& detail) {
             return ExecutionResult{s, detail};
           }),
           py::arg("status"), py::arg("detail") = "")
      .def_readonly("status", &ExecutionResult::status)
      .def_readonly("detail", &ExecutionResult::detail);
  py::class_<ExecutorBase>(m, "TrajectoryExecutor",
                           "Subclass it (or pass a callable): execute(times_s (N,), positions "
                           "(N, 7)) runs the trajectory on the robot, blocking, and returns an "
                           "ExecutionStatus, an ExecutionResult or a bool (False: failed).")
      .def(py::init<>())
      .def("execute", [](ExecutorBase&, const py::object&, const py::object&) -> py::object {
        throw py::type_error("fvp.TrajectoryExecutor subclass does not define execute");
      });
  py::class_<JointStateBase>(m, "JointStateSource",
                             "Subclass it (or pass a callable): joint_positions() -> (7,), the "
                             "slider (m) and the UR5's six joints (rad), now.")
      .def(py::init<>())
      .def("joint_positions", [](JointStateBase&) -> py::object {
        throw py::type_error("fvp.JointStateSource subclass does not define joint_positions");
      });
}

void bindModelAndWorkspace(py::module_& m) {
  py::class_<robot::ArmModel>(m, "ArmModel",
                              "The UR5 on its slider: kinematics and limits from an arm YAML "
                              "(fvp run --arm; '' for the defaults).")
      .def(py::init([](const std::string& config, const py::object& workspace_cache_dir) {
             robot::ArmConfig c =
                 config.empty() ? robot::ArmConfig{} : robot::ArmConfig::fromYamlFile(config);
             if (!workspace_cache_dir.is_none())
               c.workspace_cache_dir = workspace_cache_dir.cast<std::string>();
             return std::make_unique<robot::ArmModel>(c);
           }),
           py::arg("config") = "", py::arg("workspace_cache_dir") = py::none())
      .def(
          "camera_pose",
          [](const robot::ArmModel& a, const py::handle& q) {
            return poseToArray(a.T_world_camera(jointsFromPython(q, "ArmModel.camera_pose q")));
          },
          py::arg("q"), "T_world_camera (4, 4) of the left camera's optical frame at joints q.")
      .def("home_configuration",
           [](const robot::ArmModel& a) { return jointsToArray(a.homeConfiguration()); })
      .def_property_readonly(
          "lower_limits", [](const robot::ArmModel& a) { return jointsToArray(a.lowerLimits()); })
      .def_property_readonly(
          "upper_limits", [](const robot::ArmModel& a) { return jointsToArray(a.upperLimits()); });

  py::class_<robot::WorkspaceTree>(m, "WorkspaceTree",
                                   "The arm's reachability filter, loaded from its cache or "
                                   "built (seconds); cache problems are Python warnings.")
      .def(py::init([](const robot::ArmModel& arm) {
             std::ostringstream log;
             std::unique_ptr<robot::WorkspaceTree> tree;
             {
               py::gil_scoped_release release;
               tree = std::make_unique<robot::WorkspaceTree>(
                   robot::WorkspaceTree::loadOrBuild(arm, log));
             }
             std::istringstream lines(log.str());
             for (std::string line; std::getline(lines, line);)
               if (line.rfind("warning: ", 0) == 0)
                 if (PyErr_WarnEx(PyExc_RuntimeWarning, line.substr(9).c_str(), 1) != 0)
                   throw py::error_already_set();
             return tree;
           }),
           py::arg("arm"))
      .def(
          "reachable",
          [](const robot::WorkspaceTree& w, const py::handle& T) {
            return w.reachable(poseFromArray(T, "WorkspaceTree.reachable T_world_camera"));
          },
          py::arg("T_world_camera"))
      .def_property_readonly("from_cache", &robot::WorkspaceTree::fromCache);
}

}  // namespace

void bindPlannedArm(py::module_& m) {
  bindDriverInterfaces(m);
  bindModelAndWorkspace(m);
  py::class_<PyPlannedArm, host::nbv::Arm>(
      m, "PlannedArm",
      "The real-robot arm (an fvp.Arm): workspace-tree reachability (None: exact IK) and IK + "
      "OMPL planning against the map; each move's trajectory goes to the executor, sampled at "
      "most sample_period_s apart. Planning starts from joint_state's joints.")
      .def(py::init([](const robot::ArmModel& model, const py::object& workspace,
                       const py::object& joint_state, const py::object& executor,
                       double goal_tolerance, double sample_period_s) {
             const py::module_ fvp = py::module_::import("fvp");
             return std::make_unique<PyPlannedArm>(
                 model, workspace,
                 PythonJointState(driverCallable(joint_state, fvp.attr("JointStateSource"),
                                                 "joint_positions", "joint_state")),
                 PythonExecutor(driverCallable(executor, fvp.attr("TrajectoryExecutor"), "execute",
                                               "executor"),
                                sample_period_s),
                 goal_tolerance);
           }),
           py::arg("arm"), py::arg("workspace"), py::arg("joint_state"), py::arg("executor"),
           py::arg("goal_tolerance") = robot::kDefaultGoalTolerance,
           py::arg("sample_period_s") = 0.01, py::keep_alive<1, 2>(), py::keep_alive<1, 3>())
      .def(
          "move",
          [](PyPlannedArm& a, const py::handle& T) {
            const Eigen::Isometry3d pose = poseFromArray(T, "PlannedArm.move T_world_camera");
            robot::PlannedMove move;
            {
              py::gil_scoped_release release;
              move = a.moveToPose(pose);
            }
            return moveToDict(move);
          },
          py::arg("T_world_camera"),
          "move_to with details: status, planning_wall_s, motion_status, duration_s, "
          "execution, detail.")
      .def("joints", [](const PyPlannedArm& a) { return jointsToArray(a.joints()); })
      .def("set_reproducible_motion_planning", &PyPlannedArm::setReproducibleMotionPlanning,
           py::arg("seed"));
}

}  // namespace fvp::python
