// The parts of the fvp Python module, each binding one area into the module.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <mutex>
#include <string>

#include "fvp/accel/backend.h"
#include "fvp/host/nbv/nbv_loop.h"
#include "fvp/host/planner/view_planner.h"
#include "fvp/host/session/mapping_session.h"

namespace fvp::python {

namespace py = pybind11;

/// A backend by name ("cpu", "opencl", "vulkan", "auto"); "none" (or an engine that needs
/// none with "auto") gives null. An unavailable backend asked for by name is an error.
std::unique_ptr<accel::Backend> backendFor(const std::string& name, const std::string& engine);

/// fvp.MappingSession: the session with the backend it runs on.
struct Session {
  Session(const host::PerceptionConfig& perception, const std::string& engine,
          const std::string& backend_name, const std::string& planner, bool tsdf,
          bool register_views);
  std::unique_ptr<accel::Backend> backend;
  std::string engine;
  std::unique_ptr<host::MappingSession> session;
  /// Python threads may share a session. Every call locks it after releasing the GIL: a
  /// lock taken while holding the GIL could deadlock against a loop that calls back into
  /// Python while holding it.
  mutable std::mutex mutex;
};

/// fvp.Planner: a registered planner with the backend its kernels run on.
struct Planner {
  Planner(const std::string& name, const std::string& config_yaml, std::uint64_t seed,
          const std::string& backend_name);
  std::unique_ptr<accel::Backend> backend;
  std::unique_ptr<host::planner::ViewPlanner> planner;
  std::mutex mutex;  ///< as Session::mutex
};

/// The session's maps, or std::runtime_error naming `what` when no view placed a region yet.
host::map::MapEngine& requireMap(Session& s, const char* what);

/// Observer hooks a Python object may define: on_view(dict), on_plan(dict),
/// on_dropped_frame(str). Each call takes the GIL.
class PyObserver : public host::nbv::LoopObserver {
 public:
  explicit PyObserver(py::object target) : target_(std::move(target)) {}
  void onView(const host::nbv::ViewEvent& e) override;
  void onPlan(const host::nbv::PlanEvent& e) override;
  void onDroppedFrame(const std::string& detail) override;

 protected:
  py::object target_;
};

/// A loop's result as a dict: views, stop_reason, camera_poses, events, wall_s.
py::dict nbvResultToDict(const host::nbv::NbvResult& r);

// The module's areas, one file each (bind_*.cpp), called in this order by PYBIND11_MODULE.
void bindCore(py::module_& m);  ///< planners(), backends(), StereoIntrinsics, StereoFrame
void bindPerceptionSizing(py::module_& m);  ///< PerceptionConfig, size_captures, season
void bindSession(py::module_& m);           ///< MapEngine, MappingSession
void bindPlanners(py::module_& m);          ///< Planner, info_gain
void bindRobot(py::module_& m);             ///< Camera, Arm, CaptureResult, MoveResult
void bindPlannedArm(py::module_& m);        ///< PlannedArm, ArmModel, WorkspaceTree, drivers
void bindLoop(py::module_& m);              ///< LoopState, StopCondition, run_nbv
void bindSetup(py::module_& m);             ///< LoopClock, ClusterTarget, NbvSetup (cluster, tour)
void bindSim(py::module_& m);               ///< fvp.sim: Trial, run_trial

}  // namespace fvp::python
