// The clock the next-best-view loop's stop condition reads. On a robot it is the wall clock;
// in simulation it is a simulated clock that charges each stage (capture, mapping, TSDF,
// planning, motion) its modelled or measured time.
#pragma once

#include <chrono>

namespace fvp::host::nbv {

/// The loop's own compute, which a simulated clock charges (measured or fixed).
/// kSizing: sizing the cluster during the loop (the automatic stop's, cluster_completion.h).
/// kGoalCheck: one batch of the arm's goal checks of ranked views (Arm::checkGoal).
/// kPerception: a captured frame's stereo matching, tag detection, segmentation and clouds.
enum class LoopStage { kMapping, kTsdf, kPlanning, kSizing, kGoalCheck, kPerception };

class LoopClock {
 public:
  virtual ~LoopClock() = default;
  virtual double now_s() const = 0;
  /// The start of one loop iteration (a simulated clock keeps per-iteration charges).
  virtual void beginIteration() {}
  /// wall_s of loop compute in a stage just ran. A wall clock has counted it already.
  virtual void chargeCompute(LoopStage stage, double wall_s) {
    (void)stage;
    (void)wall_s;
  }
  /// Stereo matching's share of a view's perception (charged within kPerception), recorded
  /// so the records say how much of perception it is.
  virtual void recordStereoMatching(double wall_s) { (void)wall_s; }
};

/// Seconds of wall time since construction: the clock of a real robot's loop.
class SteadyLoopClock : public LoopClock {
 public:
  SteadyLoopClock() : start_(std::chrono::steady_clock::now()) {}
  double now_s() const override {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace fvp::host::nbv
