// A simulated world's ground truth as ground_truth.json holds it (World::groundTruthJson):
// the fruitlets' centres and sizes that sizing is scored against (sizing_score.h). Kept apart
// from the scoring so the reader builds on its own (nlohmann_json, Eigen).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace fvp::host::eval {

struct GroundTruthFruitlet {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  double size_mm = 0.0;
};

/// The fruitlets of a ground_truth.json (the simulator's World::groundTruthJson): throws
/// std::runtime_error naming `source` and the field when it is malformed.
std::vector<GroundTruthFruitlet> groundTruthFromJson(const std::string& text,
                                                     const std::string& source);

}  // namespace fvp::host::eval
