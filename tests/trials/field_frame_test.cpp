// The development worlds where the field preset's automatic stop lost its frame before the
// cluster's pose graph (docs/sizing.md "The cluster's pose graph"): world 26 (the hand-eye
// error turned the views' errors by up to 10 mm; alignments slid into wrong matches and the
// maps sat in two frames 9 mm apart: 2 of 4 fruitlets matched, 25 views) and world 5 (the
// anchor 7.1 mm off, 31 views, precision 75 %). Every view's residual against the truth is
// printed; the fused maps' frame must be recovered and every fruitlet found in both frames.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>

#include "fvp/trials/trial.h"

namespace fvp::trials {
namespace {

Eigen::Vector3d vec3(const nlohmann::json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

TEST(FieldFrame, TheWorstDevelopmentWorldsKeepTheirFrame) {
  for (const std::uint64_t seed : {26u, 5u}) {
    TrialOptions o;
    o.seed = seed;
    o.world_config = std::filesystem::path(FVP_SOURCE_DIR) / "robot/sim/config/world_field.yaml";
    o.backend = accel::BackendChoice::kCpu;
    o.clock = robot::sim::SimClock::Mode::kFixed;
    o.stop = host::nbv::StopRule::kAuto;
    const nlohmann::json result = runTrial(o);
    ASSERT_TRUE(result.contains("anchor_offset")) << "registration is the preset's setting";
    const nlohmann::json& offset = result["anchor_offset"];
    std::cout << "world " << seed << ": " << result["views"] << " views, stop "
              << result["stop_reason"] << ", frame error " << offset["frame_error_mm"]
              << " mm, after the reported shift " << offset["corrected_frame_error_mm"] << " mm\n";
    const Eigen::Vector3d frame_mm =
        vec3(offset["shift_mm"]);  // what the graph says the maps' frame error is
    for (const auto& v : result["view_log"])
      std::cout << "  view " << v["index"] << " tag " << v["tag_detected"] << " placed error "
                << vec3(v["placed_error_mm"]).transpose() << " mm, residual to the estimated frame "
                << (vec3(v["placed_error_mm"]) - frame_mm).norm() << " mm\n";
    EXPECT_EQ(result["stop_reason"], "cluster_done") << "world " << seed;
    // Registration's own bound for a calibration error is 8 mm; the frame error here is 4-5 mm
    // and must come back to within the 5 mm match gate's half.
    EXPECT_LT(offset["corrected_frame_error_mm"].get<double>(), 2.5) << "world " << seed;
    EXPECT_EQ(result["metrics"]["match_percent"].get<double>(), 100.0) << "world " << seed;
    EXPECT_EQ(result["metrics"]["precision_percent"].get<double>(), 100.0) << "world " << seed;
    EXPECT_EQ(result["metrics_tag_frame"]["match_percent"].get<double>(), 100.0)
        << "world " << seed;
  }
}

}  // namespace
}  // namespace fvp::trials
