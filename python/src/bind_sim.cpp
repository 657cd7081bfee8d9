// fvp.sim: the simulator's trials. A Trial exposes its simulated camera and arm, so that a
// Python camera and arm can wrap them and drive the same loop (tests/test_trial_loop.py).
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/nbv/arm.h"
#include "fvp/host/nbv/camera.h"
#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/trials/simulated_robot.h"
#include "fvp/trials/trial.h"

namespace fvp::python {
namespace {

trials::TrialOptions trialOptions(const std::string& planner, std::uint64_t seed, double budget_s,
                                  const std::optional<int>& max_views, const std::string& clock,
                                  const std::string& stop, bool confirm_detections,
                                  bool release_left_out, bool size_history,
                                  std::optional<bool> register_views, const std::string& backend,
                                  const std::string& engine, const std::string& world_config,
                                  const std::string& planner_config, const std::string& arm_config,
                                  const std::string& out_dir) {
  trials::TrialOptions o;
  o.planner = planner;
  o.seed = seed;
  o.budget_s = budget_s;
  o.max_views = max_views;
  o.clock = robot::sim::SimClock::modeFromString(clock);
  const auto rule = host::nbv::stopRuleFromString(stop);
  if (!rule)
    throw std::invalid_argument("stop: expected one of " + host::nbv::stopRuleNames() + ", got '" +
                                stop + "'");
  o.stop = *rule;
  o.confirm_detections = confirm_detections;
  o.release_left_out = release_left_out;
  o.record_size_history = size_history;
  o.register_views = register_views;
  o.backend = backend;
  o.engine = engine;
  o.world_config = world_config;
  o.planner_config = planner_config;
  o.arm_config = arm_config;
  o.out_dir = out_dir;
  // Warnings stay in result["warnings"]; Python callers read them there.
  return o;
}

// The keyword arguments of fvp run, in one place for Trial and run_trial.
#define FVP_TRIAL_ARGS                                                                          \
  py::kw_only(),                                                                                \
      py::arg("planner") = "fvp", py::arg("seed") = 1, py::arg("budget_s") = 180.0,             \
      py::arg("max_views") = py::none(), py::arg("clock") = "wall", py::arg("stop") = "budget", \
      py::arg("confirm_detections") = true, py::arg("release_left_out") = true,                 \
      py::arg("size_history") = false, py::arg("register_views") = py::none(),                  \
      py::arg("backend") = "auto", py::arg("engine") = "", py::arg("world_config") = "",        \
      py::arg("planner_config") = "", py::arg("arm_config") = "", py::arg("out_dir") = ""

}  // namespace

void bindSim(py::module_& m) {
  py::module_ sim = m.def_submodule("sim", "The simulated orchard and its trials (fvp run).");

  py::class_<trials::SimulatedRobot>(
      sim, "Robot",
      "The simulator as a robot: a world from a seed, its stereo camera, the UR5 on its slider "
      "and the simulated clock, for the library's fvp.NbvSetup (as a real robot's would be).")
      .def(py::init([](std::uint64_t seed, const std::string& world_config,
                       const std::string& arm_config, const std::string& clock) {
             trials::SimulatedRobotOptions o;
             o.seed = seed;
             o.world_config = world_config;
             o.arm_config = arm_config;
             o.clock = robot::sim::SimClock::modeFromString(clock);
             return std::make_unique<trials::SimulatedRobot>(o);
           }),
           py::kw_only(), py::arg("seed") = 1, py::arg("world_config") = "",
           py::arg("arm_config") = "", py::arg("clock") = "wall")
      .def_property_readonly(
          "camera", [](trials::SimulatedRobot& r) -> host::nbv::Camera& { return r.camera(); },
          py::return_value_policy::reference_internal, "The simulated camera (fvp.Camera).")
      .def_property_readonly(
          "arm", [](trials::SimulatedRobot& r) -> host::nbv::Arm& { return r.arm(); },
          py::return_value_policy::reference_internal, "The simulated UR5 on its slider (fvp.Arm).")
      .def_property_readonly(
          "clock", [](trials::SimulatedRobot& r) -> host::nbv::LoopClock& { return r.loopClock(); },
          py::return_value_policy::reference_internal,
          "The simulated clock as the loop's clock (fvp.LoopClock).")
      .def_property_readonly("targets", &trials::SimulatedRobot::clusterTargets,
                             "The world's clusters as fvp.ClusterTarget, in the world's order.");

  py::class_<trials::Trial>(sim, "Trial",
                            "One simulated trial, built and not yet run (fvp run's options "
                            "as keywords). Its camera and arm are the simulator's.")
      .def(py::init([](const std::string& planner, std::uint64_t seed, double budget_s,
                       std::optional<int> max_views, const std::string& clock,
                       const std::string& stop, bool confirm_detections, bool release_left_out,
                       bool size_history, std::optional<bool> register_views,
                       const std::string& backend, const std::string& engine,
                       const std::string& world_config, const std::string& planner_config,
                       const std::string& arm_config, const std::string& out_dir) {
             return std::make_unique<trials::Trial>(
                 trialOptions(planner, seed, budget_s, max_views, clock, stop, confirm_detections,
                              release_left_out, size_history, register_views, backend, engine,
                              world_config, planner_config, arm_config, out_dir));
           }),
           FVP_TRIAL_ARGS)
      .def_property_readonly(
          "camera", [](trials::Trial& t) -> host::nbv::Camera& { return t.simulatedCamera(); },
          py::return_value_policy::reference_internal,
          "The simulated camera (fvp.Camera): renders at a pose, charged to the simulated clock.")
      .def_property_readonly(
          "arm", [](trials::Trial& t) -> host::nbv::Arm& { return t.simulatedArm(); },
          py::return_value_policy::reference_internal,
          "The simulated UR5 on its slider (fvp.Arm): IK + OMPL, charged moves.")
      .def(
          "run",
          [](trials::Trial& t, host::nbv::Camera* camera, host::nbv::Arm* arm) {
            nlohmann::json result;
            {
              py::gil_scoped_release release;
              result = t.run(camera ? *camera : t.simulatedCamera(), arm ? *arm : t.simulatedArm());
            }
            return jsonToPython(result);
          },
          py::arg("camera") = nullptr, py::arg("arm") = nullptr,
          "Runs the loop through camera and arm (default: the simulator's), scores against the "
          "world and returns result.json's object. A trial runs once.");

  sim.def(
      "run_trial",
      [](const std::string& planner, std::uint64_t seed, double budget_s,
         std::optional<int> max_views, const std::string& clock, const std::string& stop,
         bool confirm_detections, bool release_left_out, bool size_history,
         std::optional<bool> register_views, const std::string& backend, const std::string& engine,
         const std::string& world_config, const std::string& planner_config,
         const std::string& arm_config, const std::string& out_dir) {
        const trials::TrialOptions o =
            trialOptions(planner, seed, budget_s, max_views, clock, stop, confirm_detections,
                         release_left_out, size_history, register_views, backend, engine,
                         world_config, planner_config, arm_config, out_dir);
        nlohmann::json result;
        {
          py::gil_scoped_release release;
          result = trials::runTrial(o);
        }
        return jsonToPython(result);
      },
      FVP_TRIAL_ARGS, "fvp run as a function: result.json's object.");
  m.attr("run_trial") = sim.attr("run_trial");
}

}  // namespace fvp::python
