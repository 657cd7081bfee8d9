// Fruitlets of one cluster followed from one visit to the next (docs/season.md): a one-to-one
// assignment by position in the cluster tag's frame, gated by how far a fruitlet can move and
// how much it can grow between the visits, with "gone" (an earlier fruitlet without a later
// one: fell off, or not found) and "new" (a later one without an earlier) allowed.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace fvp::host::season {

/// A fruitlet as one visit sized it: its centre in the cluster tag's frame and its diameter.
struct VisitFruitlet {
  Eigen::Vector3d center_tag_m = Eigen::Vector3d::Zero();
  double size_mm = 0.0;
};

struct AssociationConfig {
  /// The farthest a fruitlet's centre moves between visits (stems droop a few millimetres as
  /// fruitlets grow, plus each visit's registration error): beyond, it is another fruitlet.
  double max_center_shift_m = 0.008;
  /// The spread of that shift, for the cost and the confidence.
  double center_sigma_m = 0.002;
  /// The fastest a fruitlet grows (about 1 mm a day in warm weather) with room for two
  /// sizings' errors, and the most a later size may fall below an earlier one (two sizings'
  /// errors: a fruitlet does not shrink).
  double max_growth_mm_per_day = 1.5;
  double max_shrink_mm = 1.0;
  /// Throws std::invalid_argument naming the field: a value not > 0 (shrink: >= 0).
  void validate() const;
};

struct Association {
  std::vector<int> later_of_earlier;  ///< per earlier fruitlet: its later index, or -1 (gone)
  std::vector<int> earlier_of_later;  ///< per later fruitlet: its earlier index, or -1 (new)
  /// Per earlier fruitlet with a later one: how much more likely this pairing is than every
  /// other its two fruitlets could have had (in [0, 1]); NaN for a gone one.
  std::vector<double> confidence;
};

/// The one-to-one assignment with the most pairs within the gates (the centre within
/// max_center_shift_m, the size change within [-max_shrink_mm, max_growth_mm_per_day * days]),
/// and among those the least summed squared shift (assignOneToOne: exact for up to 16 later
/// fruitlets). days_since[e]: the days from earlier fruitlet e's size to the later visit, each
/// >= 0 (fruitlets last seen on different visits each get their own growth gate).
Association associateFruitlets(const std::vector<VisitFruitlet>& earlier,
                               const std::vector<VisitFruitlet>& later,
                               const std::vector<double>& days_since,
                               const AssociationConfig& config = {});

/// The same with every earlier fruitlet sized days_between before the later visit.
Association associateFruitlets(const std::vector<VisitFruitlet>& earlier,
                               const std::vector<VisitFruitlet>& later, double days_between,
                               const AssociationConfig& config = {});

}  // namespace fvp::host::season
