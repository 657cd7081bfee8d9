#include "fvp/robot/sim/simulated_loop_clock.h"

namespace fvp::robot::sim {

void SimulatedLoopClock::chargeCompute(host::nbv::LoopStage stage, double wall_s) {
  switch (stage) {
    case host::nbv::LoopStage::kMapping:
      clock_.chargeCompute(ClockStage::kMapping, wall_s);
      return;
    case host::nbv::LoopStage::kTsdf:
      clock_.chargeCompute(ClockStage::kTsdf, wall_s);
      return;
    case host::nbv::LoopStage::kPlanning:
      clock_.chargeCompute(ClockStage::kPlanning, wall_s);
      return;
    case host::nbv::LoopStage::kSizing:
      clock_.chargeCompute(ClockStage::kSizing, wall_s);
      return;
    case host::nbv::LoopStage::kGoalCheck:
      clock_.chargeCompute(ClockStage::kGoalCheck, wall_s);
      return;
    case host::nbv::LoopStage::kPerception:
      clock_.chargeCompute(ClockStage::kPerception, wall_s);
      return;
  }
}

}  // namespace fvp::robot::sim
