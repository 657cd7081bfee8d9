// The next-best-view loop over Python objects: the stop condition may be a Python
// predicate, an observer's hooks are called as the loop goes, and run_nbv drives a camera and
// an arm (bind_robot.cpp) with a session and a planner.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <optional>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/nbv/nbv_loop.h"

namespace fvp::python {

void PyObserver::onView(const host::nbv::ViewEvent& e) {
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
void PyObserver::onPlan(const host::nbv::PlanEvent& e) {
  py::gil_scoped_acquire gil;
  if (!py::hasattr(target_, "on_plan")) return;
  py::dict d;
  d["iteration"] = e.iteration;
  d["candidates"] = e.step->candidates.size();
  d["moved"] = e.step->moved();
  d["move_attempts"] = e.step->move_attempts;
  d["ended_by_failed_plans"] = e.step->gave_up;
  d["planning_s"] = e.planning_s;
  d["now_s"] = e.now_s;
  target_.attr("on_plan")(d);
}
void PyObserver::onDroppedFrame(const std::string& detail) {
  py::gil_scoped_acquire gil;
  if (py::hasattr(target_, "on_dropped_frame")) target_.attr("on_dropped_frame")(detail);
}

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
  events["iterations_ended_by_failed_plans"] = e.iterations_ended_by_failed_plans;
  events["retreats"] = e.retreats;
  events["goal_checks"] = e.goal_checks;
  events["candidates_rejected_no_ik"] = e.rejected_no_ik;
  events["candidates_rejected_no_collision_free_ik"] = e.rejected_no_collision_free_ik;
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
  wall["goal_check"] = w.goal_check;
  wall["motion_planning"] = w.motion_planning;
  wall["moving"] = w.moving;
  d["wall_s"] = wall;
  return d;
}

void bindLoop(py::module_& m) {
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
         int max_consecutive_dropped_frames, std::size_t max_failed_plans) {
        host::nbv::SteadyLoopClock clock;
        host::nbv::NbvLoopOptions options;
        options.max_consecutive_dropped_frames = max_consecutive_dropped_frames;
        options.max_failed_plans = max_failed_plans;
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
      py::arg("max_failed_plans") = host::nbv::kDefaultMaxFailedPlans,
      "The next-best-view loop on the wall clock: capture at the arm's pose, perceive and map, "
      "plan, move, until stop holds; a planning iteration ends after max_failed_plans timed-out "
      "or pathless motion plans (0: no limit). Returns views, stop_reason, camera_poses, events, "
      "wall_s.");
}

}  // namespace fvp::python
