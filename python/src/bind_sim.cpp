// fvp.sim: the simulator's trials. A Trial exposes its simulated camera and arm, so that a
// Python camera and arm can wrap them and drive the same loop (tests/test_trial_loop.py).
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/nbv/arm.h"
#include "fvp/host/nbv/camera.h"
#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/trials/simulated_robot.h"
#include "fvp/trials/trial.h"
#include "fvp/trials/trial_fields.h"
#include "run_keywords.h"

namespace fvp::python {
namespace {

/// fvp run's settings as keywords (trials/trial_fields.h), and out_dir.
trials::TrialOptions trialOptions(const py::kwargs& kw, const char* owner) {
  trials::TrialOptions o;
  RunKeywords keywords(kw, owner);
  trials::visitTrialFields(o, keywords);
  keywords.take("out_dir", o.out_dir);
  keywords.take("remembered_visit", o.remembered_visit);
  keywords.finish();
  // Warnings stay in result["warnings"]; Python callers read them there.
  return o;
}

/// The keywords' docstring: every setting with its default.
std::string trialKeywordDoc() {
  return keywordDoc(
             trials::TrialOptions{},
             [](const trials::TrialOptions& o, auto&& visit) {
               trials::visitTrialFields(o, visit);
             },
             [](const auto& value) {
               using trials::settingJson;
               return settingJson(value);
             }) +
         "  out_dir (default: \"\"): where result.json and the trial's files go (empty: "
         "nothing is written)\n"
         "  remembered_visit (default: \"\"): an earlier visit of the same tree (its result.json "
         "or directory): each cluster starts from what it learned (docs/season.md)\n";
}

}  // namespace

void bindSim(py::module_& m) {
  py::module_ sim = m.def_submodule("sim", "The simulated orchard and its trials (fvp run).");

  py::class_<trials::SimulatedRobot>(
      sim, "Robot",
      "The simulator as a robot: a world from a seed, its stereo camera, the UR5 on its slider "
      "and the simulated clock, for the library's fvp.NbvSetup (as a real robot's would be). "
      "fixed_perception_time_s: perception's charge a view on the fixed clock, that of the "
      "setup's stereo pass: 0.4 s for SGBM's (the default), 0.2 s for "
      "NbvSetup(guided_stereo=True).")
      .def(py::init([](std::uint64_t seed, const std::string& world_config,
                       const std::string& arm_config, const std::string& clock,
                       std::optional<double> season_day, double fixed_perception_time_s) {
             if (!std::isfinite(fixed_perception_time_s) || fixed_perception_time_s < 0.0)
               throw py::value_error(
                   "sim.Robot: fixed_perception_time_s: expected a number of seconds >= 0, got " +
                   std::to_string(fixed_perception_time_s));
             trials::SimulatedRobotOptions o;
             o.fixed_perception_time_s = fixed_perception_time_s;
             o.seed = seed;
             o.world_config = world_config;
             o.season_day = season_day;
             o.arm_config = arm_config;
             o.clock = robot::sim::SimClock::modeFromString(clock);
             return std::make_unique<trials::SimulatedRobot>(o);
           }),
           py::kw_only(), py::arg("seed") = 1, py::arg("world_config") = "",
           py::arg("arm_config") = "", py::arg("clock") = "wall",
           py::arg("season_day") = py::none(),
           py::arg("fixed_perception_time_s") = robot::sim::kDefaultFixedPerceptionTimeS)
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

  static const std::string trial_doc =
      "One simulated trial, built and not yet run (fvp run's settings as keywords). Its camera "
      "and arm are the simulator's. Keywords:\n" +
      trialKeywordDoc();
  py::class_<trials::Trial>(sim, "Trial", trial_doc.c_str())
      .def(py::init([](const py::kwargs& kw) {
        return std::make_unique<trials::Trial>(trialOptions(kw, "fvp.sim.Trial"));
      }))
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

  static const std::string run_doc =
      "fvp run as a function: result.json's object. Keywords:\n" + trialKeywordDoc();
  sim.def(
      "run_trial",
      [](const py::kwargs& kw) {
        const trials::TrialOptions o = trialOptions(kw, "fvp.sim.run_trial");
        nlohmann::json result;
        {
          py::gil_scoped_release release;
          result = trials::runTrial(o);
        }
        return jsonToPython(result);
      },
      run_doc.c_str());
  m.attr("run_trial") = sim.attr("run_trial");
}

}  // namespace fvp::python
