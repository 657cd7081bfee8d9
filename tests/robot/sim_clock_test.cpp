// The simulated clock: charges add up, fixed mode is deterministic, records per iteration.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "fvp/robot/sim/sim_clock.h"

namespace fvp::robot::sim {
namespace {

TEST(SimClock, AddsUpToTheSumOfItsCharges) {
  SimClock clock(SimClock::Mode::kWall, 0.2, 0.1);
  double expected = 0.0;
  for (int i = 0; i < 5; ++i) {
    clock.beginIteration();
    clock.chargeCapture();
    clock.chargeCompute(ClockStage::kMapping, 0.011 * i);
    clock.chargeCompute(ClockStage::kTsdf, 0.003);
    clock.chargeCompute(ClockStage::kPlanning, 0.05);
    clock.chargeMotionPlanning(0.02, 0.5);  // wall mode: the measured time
    clock.chargeMotion(1.5 + i);
    clock.recordUncharged(0.7, 0.4);  // not charged
    expected += 0.2 + 0.011 * i + 0.003 + 0.05 + 0.02 + 1.5 + i;
  }
  EXPECT_NEAR(clock.now_s(), expected, 1e-12);
  double sum = 0.0;
  for (const IterationCharges& it : clock.iterations()) sum += it.total_s();
  EXPECT_NEAR(sum, clock.now_s(), 1e-12);
  ASSERT_EQ(clock.iterations().size(), 5u);
  EXPECT_DOUBLE_EQ(clock.iterations()[3].charged(ClockStage::kMotion), 4.5);
  const auto json = nlohmann::json::parse(clock.toJson());
  EXPECT_EQ(json["iterations"].size(), 5u);
  EXPECT_DOUBLE_EQ(json["iterations"][2]["mapping_s"].get<double>(), 0.022);
  EXPECT_DOUBLE_EQ(json["iterations"][2]["rendering_wall_s"].get<double>(), 0.7);
}

TEST(SimClock, FixedModeChargesConstantsAndKeepsTheMeasuredTime) {
  SimClock clock(SimClock::Mode::kFixed, 0.2, 0.1);
  clock.chargeCapture();  // opens the first iteration itself
  clock.chargeCompute(ClockStage::kMapping, 3.7);
  clock.chargeCompute(ClockStage::kPlanning, 0.001);
  clock.chargeMotion(2.0);
  EXPECT_NEAR(clock.now_s(), 0.2 + 0.1 + 0.1 + 2.0, 1e-12);
  EXPECT_DOUBLE_EQ(clock.iterations()[0].measured_s[static_cast<int>(ClockStage::kMapping)], 3.7);
  clock.chargeCompute(ClockStage::kGoalCheck, 0.002);  // a batch of goal checks: one stage
  EXPECT_NEAR(clock.now_s(), 0.2 + 0.1 + 0.1 + 2.0 + 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(
      nlohmann::json::parse(clock.toJson())["iterations"][0]["goal_check_s"].get<double>(), 0.1);
  EXPECT_THROW(clock.chargeCompute(ClockStage::kMotion, 1.0), std::invalid_argument);
  EXPECT_THROW(clock.chargeMotion(-1.0), std::invalid_argument);
}

TEST(SimClock, PerceptionIsChargedLikeEveryComputeStage) {
  // Fixed mode: perception's own constant (stereo matching dominates it), not the 0.1 s of
  // the lighter stages; the measured time is kept beside it.
  SimClock fixed(SimClock::Mode::kFixed, 0.2, 0.1, 0.4);
  fixed.chargeCapture();
  fixed.chargeCompute(ClockStage::kPerception, 0.37);
  fixed.chargeCompute(ClockStage::kMapping, 0.05);
  EXPECT_NEAR(fixed.now_s(), 0.2 + 0.4 + 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(fixed.iterations()[0].charged(ClockStage::kPerception), 0.4);
  EXPECT_DOUBLE_EQ(fixed.iterations()[0].measured_s[static_cast<int>(ClockStage::kPerception)],
                   0.37);
  const auto row = nlohmann::json::parse(fixed.toJson())["iterations"][0];
  EXPECT_DOUBLE_EQ(row["perception_s"].get<double>(), 0.4);
  EXPECT_DOUBLE_EQ(row["measured_wall"]["perception_s"].get<double>(), 0.37);
  // Wall mode: as measured.
  SimClock wall(SimClock::Mode::kWall, 0.2, 0.1, 0.4);
  wall.chargeCompute(ClockStage::kPerception, 0.25);
  EXPECT_NEAR(wall.now_s(), 0.25, 1e-12);
  EXPECT_THROW(SimClock(SimClock::Mode::kFixed, 0.2, 0.1, -0.4), std::invalid_argument);
}

TEST(SimClock, ABadChargeNamesItsField) {
  const auto messageOf = [](double capture_s, double stage_s, double perception_s) {
    try {
      SimClock(SimClock::Mode::kFixed, capture_s, stage_s, perception_s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(messageOf(-1.0, 0.1, 0.4).find("capture_time_s"), std::string::npos);
  EXPECT_NE(messageOf(0.2, NAN, 0.4).find("fixed_stage_time_s"), std::string::npos);
  EXPECT_NE(messageOf(0.2, 0.1, -0.4).find("fixed_perception_time_s"), std::string::npos);
  EXPECT_NE(messageOf(-1e-9, 0.1, 0.4).find("got -1e-09"), std::string::npos);
  EXPECT_NE(messageOf(0.2, 0.1, INFINITY).find("fixed_perception_time_s"), std::string::npos);
  EXPECT_EQ(messageOf(0.2, 0.1, 0.4), "no error");
}

TEST(SimClock, AMotionPlanIsChargedAtLeastItsWorkOnTheFixedClock) {
  // Fixed mode: the stage's constant for a plan lighter than it, the plan's work on the
  // reference computer beyond (a timed-out plan spends its whole budget).
  SimClock fixed(SimClock::Mode::kFixed, 0.2, 0.1);
  fixed.chargeMotionPlanning(0.004, 0.03);
  EXPECT_NEAR(fixed.now_s(), 0.1, 1e-12);
  fixed.chargeMotionPlanning(3.5, 1.1);
  EXPECT_NEAR(fixed.now_s(), 0.1 + 1.1, 1e-12);
  EXPECT_DOUBLE_EQ(fixed.iterations()[0].charged(ClockStage::kMotionPlanning), 1.2);
  EXPECT_DOUBLE_EQ(fixed.iterations()[0].measured_s[static_cast<int>(ClockStage::kMotionPlanning)],
                   3.504);
  EXPECT_THROW(fixed.chargeMotionPlanning(0.1, -1.0), std::invalid_argument);
  EXPECT_THROW(fixed.chargeMotionPlanning(0.1, std::nan("")), std::invalid_argument);
  EXPECT_THROW(fixed.chargeCompute(ClockStage::kMotionPlanning, 0.1), std::invalid_argument);
  // Wall mode: as measured, whatever the work.
  SimClock wall(SimClock::Mode::kWall, 0.2, 0.1);
  wall.chargeMotionPlanning(0.3, 5.0);
  EXPECT_NEAR(wall.now_s(), 0.3, 1e-12);
}

TEST(SimClock, ModeFromString) {
  EXPECT_EQ(SimClock::modeFromString("fixed"), SimClock::Mode::kFixed);
  EXPECT_EQ(SimClock::modeFromString("wall"), SimClock::Mode::kWall);
  EXPECT_THROW(SimClock::modeFromString("sundial"), std::invalid_argument);
}

}  // namespace
}  // namespace fvp::robot::sim
