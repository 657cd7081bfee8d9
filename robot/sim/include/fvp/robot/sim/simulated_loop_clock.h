// The simulated clock as the next-best-view loop's clock: the loop's compute charged as
// measured (clock wall) or as a constant (clock fixed), perception included.
#pragma once

#include "fvp/host/nbv/loop_clock.h"
#include "fvp/robot/sim/sim_clock.h"

namespace fvp::robot::sim {

/// The simulated clock as the loop's clock: compute charged as measured (or fixed).
class SimulatedLoopClock : public host::nbv::LoopClock {
 public:
  explicit SimulatedLoopClock(SimClock& clock) : clock_(clock) {}
  double now_s() const override { return clock_.now_s(); }
  void beginIteration() override { clock_.beginIteration(); }
  void chargeCompute(host::nbv::LoopStage stage, double wall_s) override;
  void recordStereoMatching(double wall_s) override { clock_.recordUncharged(0.0, wall_s); }

 private:
  SimClock& clock_;
};

}  // namespace fvp::robot::sim
