// The fvp Python module (docs/python.md), bound area by area: core types, perception and
// sizing, the mapping session, the planners, the robot's camera and arm, the loop, and the
// simulator's trials (fvp.sim).
#include "bindings.h"

PYBIND11_MODULE(fvp, m) {
  m.doc() = "fvp: fruitlet sizing with next-best-view planning (docs/python.md)";
  fvp::python::bindCore(m);
  fvp::python::bindPerceptionSizing(m);
  fvp::python::bindSession(m);
  fvp::python::bindPlanners(m);
  fvp::python::bindRobot(m);
  fvp::python::bindPlannedArm(m);
  fvp::python::bindLoop(m);
  fvp::python::bindSetup(m);
  fvp::python::bindSim(m);
}
