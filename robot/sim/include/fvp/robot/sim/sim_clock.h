// The simulated clock (docs/design.md section 7), a simulator part (a robot's loop runs on
// the wall clock): every iteration is charged a fixed capture time (trigger, flash exposure
// and both images' transfer), the measured wall time of perception (stereo matching, tag,
// segmentation, clouds), mapping, TSDF integration, planning and motion planning, and the
// trajectory's duration. Mode `fixed` charges a constant per compute stage instead of the
// measured time (a motion plan at least its validity checks' time), for deterministic runs.
// Every charge is kept per iteration; the wall time of rendering is recorded, not charged (a
// simulator cost).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace fvp::robot::sim {

/// kGoalCheck: the arm's goal checks of ranked views (IK + collision, host::nbv::Arm::checkGoal),
/// charged per batch. kPerception: a frame's stereo matching, tag detection, segmentation and
/// clouds. Stages added later come last, so the earlier ones keep their places in the records.
enum class ClockStage {
  kCapture,
  kMapping,
  kTsdf,
  kPlanning,
  kMotionPlanning,
  kMotion,
  kSizing,
  kGoalCheck,
  kPerception
};
inline constexpr int kClockStages = 9;
const char* toString(ClockStage stage);

struct IterationCharges {
  double charged_s[kClockStages] = {};   ///< per ClockStage, simulated seconds
  double measured_s[kClockStages] = {};  ///< wall time measured for the compute stages
  double rendering_wall_s = 0.0;         ///< not charged (simulator cost)
  double sgbm_wall_s = 0.0;              ///< stereo matching's share of measured perception
  double charged(ClockStage stage) const { return charged_s[static_cast<int>(stage)]; }
  double total_s() const;
};

/// Trigger, flash exposure and both images' transfer; the stereo matching is charged as
/// perception (before issue 41 this charge stood for a GPU stereo network as well).
inline constexpr double kDefaultCaptureTimeS = 0.2;
inline constexpr double kDefaultFixedStageTimeS = 0.1;  ///< per compute stage, mode fixed
/// Perception's charges in mode fixed, from BM_View's perception stage on the cpu backend,
/// 2-core AMD EPYC (docs/performance.md), rounded up to 0.1 s as the other stages' 0.1 s is
/// above their measured times. With the guided stereo kernels' full-resolution pass
/// (NbvSetupOptions::guided_stereo): 155 ms (stereo 136 ms of it) at 0a8b737.
inline constexpr double kGuidedFixedPerceptionTimeS = 0.2;
/// With OpenCV SGBM's full-resolution pass (the default): set when it measured 368 ms (stereo
/// 322 ms); 251 ms (stereo 233 ms) at 0a8b737, still below it.
inline constexpr double kSgbmFixedPerceptionTimeS = 0.4;
inline constexpr double kDefaultFixedPerceptionTimeS = kSgbmFixedPerceptionTimeS;
/// The fixed perception charge of a run with or without the guided stereo pass.
inline constexpr double fixedPerceptionTimeS(bool guided_stereo) {
  return guided_stereo ? kGuidedFixedPerceptionTimeS : kSgbmFixedPerceptionTimeS;
}

class SimClock {
 public:
  enum class Mode { kWall, kFixed };
  SimClock(Mode mode, double capture_time_s = kDefaultCaptureTimeS,
           double fixed_stage_time_s = kDefaultFixedStageTimeS,
           double fixed_perception_time_s = kDefaultFixedPerceptionTimeS);
  /// "wall" or "fixed" (fvp run --clock); throws std::invalid_argument otherwise.
  static Mode modeFromString(const std::string& mode) {
    if (mode == modeName(Mode::kWall)) return Mode::kWall;
    if (mode == modeName(Mode::kFixed)) return Mode::kFixed;
    throw std::invalid_argument("simulated clock: expected mode wall or fixed, got '" + mode + "'");
  }
  /// "wall" or "fixed".
  static const char* modeName(Mode mode) { return mode == Mode::kFixed ? "fixed" : "wall"; }

  /// Opens the next iteration's record (charges before the first call open one).
  void beginIteration();
  void chargeCapture();
  /// A compute stage (perception, mapping, TSDF, planning, sizing for an automatic stop, a
  /// batch of goal checks) that took measured_wall_s; motion plans: chargeMotionPlanning.
  void chargeCompute(ClockStage stage, double measured_wall_s);
  /// A motion plan that took measured_wall_s and whose work on the reference computer takes
  /// reference_work_s (its validity checks at the rate that sets the reproducible check
  /// budgets, MotionPlanner::setReproducible). Mode fixed charges the larger of that and the
  /// stage's constant: a plan that spends its whole budget costs what a robot's time-limited
  /// planner (planning_time_s) would spend, not the constant.
  void chargeMotionPlanning(double measured_wall_s, double reference_work_s);
  void chargeMotion(double duration_s);
  /// Records what is not charged apart: the renderer's wall time (a simulator cost) and
  /// stereo matching's share of the perception already charged.
  void recordUncharged(double rendering_wall_s, double sgbm_wall_s);

  double now_s() const { return now_s_; }
  Mode mode() const { return mode_; }
  const std::vector<IterationCharges>& iterations() const { return iterations_; }
  /// {"mode", "sim_time_s", "iterations": [{"capture_s", "mapping_s", ...}]} for result.json.
  std::string toJson() const;

 private:
  void charge(ClockStage stage, double seconds);
  IterationCharges& current();

  Mode mode_;
  double capture_time_s_, fixed_stage_time_s_, fixed_perception_time_s_;
  double now_s_ = 0.0;
  std::vector<IterationCharges> iterations_;
};

}  // namespace fvp::robot::sim
