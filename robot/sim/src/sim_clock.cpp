#include "fvp/robot/sim/sim_clock.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fvp::robot::sim {

const char* toString(ClockStage stage) {
  switch (stage) {
    case ClockStage::kCapture:
      return "capture";
    case ClockStage::kMapping:
      return "mapping";
    case ClockStage::kTsdf:
      return "tsdf";
    case ClockStage::kPlanning:
      return "planning";
    case ClockStage::kMotionPlanning:
      return "motion_planning";
    case ClockStage::kMotion:
      return "motion";
    case ClockStage::kSizing:
      return "sizing";
    case ClockStage::kGoalCheck:
      return "goal_check";
    case ClockStage::kPerception:
      return "perception";
  }
  return "unknown";
}

double IterationCharges::total_s() const {
  double sum = 0.0;
  for (double s : charged_s) sum += s;
  return sum;
}

SimClock::SimClock(Mode mode, double capture_time_s, double fixed_stage_time_s,
                   double fixed_perception_time_s)
    : mode_(mode),
      capture_time_s_(capture_time_s),
      fixed_stage_time_s_(fixed_stage_time_s),
      fixed_perception_time_s_(fixed_perception_time_s) {
  const auto require = [](const char* field, double seconds) {
    if (!(seconds >= 0.0 && std::isfinite(seconds))) {
      std::ostringstream message;
      message << "SimClock: " << field << ": expected finite seconds >= 0, got " << seconds;
      throw std::invalid_argument(message.str());
    }
  };
  require("capture_time_s", capture_time_s);
  require("fixed_stage_time_s", fixed_stage_time_s);
  require("fixed_perception_time_s", fixed_perception_time_s);
}

void SimClock::beginIteration() {
  iterations_.emplace_back();
}

IterationCharges& SimClock::current() {
  if (iterations_.empty()) beginIteration();
  return iterations_.back();
}

void SimClock::charge(ClockStage stage, double seconds) {
  if (!(seconds >= 0.0)) throw std::invalid_argument("SimClock: negative or NaN charge");
  current().charged_s[static_cast<int>(stage)] += seconds;
  now_s_ += seconds;
}

void SimClock::chargeCapture() {
  charge(ClockStage::kCapture, capture_time_s_);
}

void SimClock::chargeCompute(ClockStage stage, double measured_wall_s) {
  if (stage == ClockStage::kCapture || stage == ClockStage::kMotion)
    throw std::invalid_argument("SimClock::chargeCompute: not a compute stage");
  if (stage == ClockStage::kMotionPlanning)
    throw std::invalid_argument("SimClock::chargeCompute: a motion plan is chargeMotionPlanning's");
  current().measured_s[static_cast<int>(stage)] += measured_wall_s;
  if (mode_ == Mode::kWall)
    charge(stage, measured_wall_s);
  else
    charge(stage,
           stage == ClockStage::kPerception ? fixed_perception_time_s_ : fixed_stage_time_s_);
}

void SimClock::chargeMotionPlanning(double measured_wall_s, double reference_work_s) {
  if (!(reference_work_s >= 0.0))
    throw std::invalid_argument("SimClock::chargeMotionPlanning: negative or NaN work");
  current().measured_s[static_cast<int>(ClockStage::kMotionPlanning)] += measured_wall_s;
  charge(ClockStage::kMotionPlanning,
         mode_ == Mode::kWall ? measured_wall_s : std::max(fixed_stage_time_s_, reference_work_s));
}

void SimClock::chargeMotion(double duration_s) {
  charge(ClockStage::kMotion, duration_s);
}

void SimClock::recordUncharged(double rendering_wall_s, double sgbm_wall_s) {
  current().rendering_wall_s += rendering_wall_s;
  current().sgbm_wall_s += sgbm_wall_s;
}

std::string SimClock::toJson() const {
  nlohmann::ordered_json json;
  json["mode"] = mode_ == Mode::kFixed ? "fixed" : "wall";
  json["sim_time_s"] = now_s_;
  json["iterations"] = nlohmann::ordered_json::array();
  for (const IterationCharges& it : iterations_) {
    nlohmann::ordered_json row;
    for (int s = 0; s < kClockStages; ++s)
      row[std::string(toString(static_cast<ClockStage>(s))) + "_s"] = it.charged_s[s];
    nlohmann::ordered_json measured;
    for (int s = 0; s < kClockStages; ++s) {
      const auto stage = static_cast<ClockStage>(s);
      if (stage != ClockStage::kCapture && stage != ClockStage::kMotion)
        measured[std::string(toString(stage)) + "_s"] = it.measured_s[s];
    }
    row["measured_wall"] = measured;
    row["rendering_wall_s"] = it.rendering_wall_s;
    row["sgbm_wall_s"] = it.sgbm_wall_s;
    row["total_s"] = it.total_s();
    json["iterations"].push_back(row);
  }
  return json.dump();
}

}  // namespace fvp::robot::sim
