// Object ids of the simulator's id layer (RenderedView::ground_truth.object_id, CV_32S):
// which world object each pixel of a rendered left image shows.
#pragma once

namespace fvp::robot::sim {

inline constexpr int kBackgroundId = 0;     ///< background / sky
inline constexpr int kFirstFruitletId = 1;  ///< fruitlet i has id kFirstFruitletId + i
inline constexpr int kMaxFruitlets = 64;
inline constexpr int kFirstLeafId = 100;  ///< leaf k has id kFirstLeafId + k
inline constexpr int kTreeId = 10000;     ///< trunk and branches
inline constexpr int kTagId = 20000;      ///< the AprilTag and its backing plate
inline bool isFruitletId(int id) {
  return id >= kFirstFruitletId && id < kFirstFruitletId + kMaxFruitlets;
}

}  // namespace fvp::robot::sim
