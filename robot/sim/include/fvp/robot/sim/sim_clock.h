// The simulated clock (docs/design.md section 7), a simulator part (a robot's loop runs on
// the wall clock): every iteration is charged a fixed capture time
// (exposure + a GPU stereo network), the measured wall time of mapping, TSDF integration,
// planning and motion planning, and the trajectory's duration. Mode `fixed` charges a
// constant per compute stage instead of the measured time, for deterministic tests. Every
// charge is kept per iteration; the wall time of rendering and SGBM is recorded, not charged.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace fvp::robot::sim {

/// kGoalCheck: the arm's goal checks of ranked views (IK + collision, host::nbv::Arm::checkGoal),
/// charged per batch; last, so the earlier stages keep their places in the records.
enum class ClockStage {
  kCapture,
  kMapping,
  kTsdf,
  kPlanning,
  kMotionPlanning,
  kMotion,
  kSizing,
  kGoalCheck
};
inline constexpr int kClockStages = 8;
const char* toString(ClockStage stage);

struct IterationCharges {
  double charged_s[kClockStages] = {};   ///< per ClockStage, simulated seconds
  double measured_s[kClockStages] = {};  ///< wall time measured for the compute stages
  double rendering_wall_s = 0.0;         ///< not charged (simulator cost)
  double sgbm_wall_s = 0.0;              ///< not charged (stands in for the capture charge)
  double charged(ClockStage stage) const { return charged_s[static_cast<int>(stage)]; }
  double total_s() const;
};

inline constexpr double kDefaultCaptureTimeS = 0.2;     ///< exposure + a GPU stereo network
inline constexpr double kDefaultFixedStageTimeS = 0.1;  ///< per compute stage, mode fixed

class SimClock {
 public:
  enum class Mode { kWall, kFixed };
  SimClock(Mode mode, double capture_time_s = kDefaultCaptureTimeS,
           double fixed_stage_time_s = kDefaultFixedStageTimeS);
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
  /// A compute stage (mapping, TSDF, planning, motion planning, sizing for an automatic stop,
  /// a batch of goal checks) that took measured_wall_s.
  void chargeCompute(ClockStage stage, double measured_wall_s);
  void chargeMotion(double duration_s);
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
  double capture_time_s_, fixed_stage_time_s_;
  double now_s_ = 0.0;
  std::vector<IterationCharges> iterations_;
};

}  // namespace fvp::robot::sim
