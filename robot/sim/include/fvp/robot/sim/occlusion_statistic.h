// Occlusion statistic of a view (docs/design.md §8): per fruitlet, the fraction of its silhouette
// that is visible compared with a render of the same view without leaves, from the
// simulator's object-id layers.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace fvp::robot::sim {

struct FruitletVisibility {
  int object_id = 0;
  long visible_px = 0;            ///< pixels with this id in the normal render
  long unoccluded_px = 0;         ///< pixels with this id in the render without leaves
  double visible_fraction = 0.0;  ///< visible / unoccluded (0 if unoccluded is 0)
};

class OcclusionStatistic {
 public:
  /// Both CV_32S id maps of the same view; fruitlets with no pixel even without leaves (out
  /// of view, or behind a branch) are listed with unoccluded_px 0 and not averaged.
  static OcclusionStatistic compute(const cv::Mat& ids_with_leaves,
                                    const cv::Mat& ids_without_leaves);

  const std::vector<FruitletVisibility>& fruitlets() const { return fruitlets_; }
  /// Mean visible fraction over the fruitlets in view; 0 if none.
  double meanVisibleFraction() const { return mean_visible_fraction_; }
  int fruitletsInView() const { return in_view_; }

 private:
  std::vector<FruitletVisibility> fruitlets_;
  double mean_visible_fraction_ = 0.0;
  int in_view_ = 0;
};

}  // namespace fvp::robot::sim
