// A season's visits turned into the grower's answer (docs/season.md): each cluster's
// fruitlets followed across the visits, their growth rates, predicted fates and the
// predicted fruit set of each cluster and of the whole sample.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "fvp/host/season/fruitlet_association.h"
#include "fvp/host/season/fruitlet_fate.h"
#include "fvp/host/season/growth_rate.h"
#include "fvp/host/season/season_visit.h"

namespace fvp::host::season {

struct SeasonConfig {
  AssociationConfig association;
  FateConfig fate;
  /// What the images of one visit share and their spread cannot show (segmentation and
  /// occlusion alike in every view of a visit): added in quadrature to each size's stated
  /// standard error before a rate is fitted. Measured on development seasons
  /// (docs/season.md "The sizes' errors"); 0 takes the stated errors as they are.
  double size_error_floor_mm = 0.14;
  void validate() const;
};

/// One fruitlet as one visit sized it, on its track.
struct TrackedSize {
  std::size_t visit = 0;  ///< index in the season's visits (in day order)
  double day = 0.0;
  SizedFruitlet sized;
  /// The association's confidence in linking it to the track's earlier size; NaN first.
  double association_confidence = std::numeric_limits<double>::quiet_NaN();
  /// Its place among that visit's cluster's fruitlets (a result's sized_fruitlets order).
  std::size_t index_in_visit = 0;
};

/// One fruitlet over the season: its sizes, its growth rate and its predicted fate.
struct FruitletTrack {
  int tag_id = 0;
  std::vector<TrackedSize> sizes;
  /// Not found on the cluster's last visit that saw its tag: fell off (or hidden); counted
  /// as not set.
  bool gone = false;
  /// Sized on one visit only, neither the cluster's first nor its last that saw its tag: no
  /// fruitlet appears after bloom, so most likely a false detection. Neither gone nor counted
  /// in the fruit set.
  bool unconfirmed = false;
  GrowthRate rate;
  FatePrediction fate;  ///< kUnknown for a gone fruitlet (its fate is known: it is off)
};

/// Predicted fruit set of some tracks: the expected share set among those with a fate or
/// gone (a gone fruitlet counts as dropped), and its standard error.
struct FruitSet {
  double percent = std::numeric_limits<double>::quiet_NaN();
  double standard_error_percent = std::numeric_limits<double>::quiet_NaN();
  std::size_t persisting = 0, abscising = 0, gone = 0, unknown = 0, unconfirmed = 0;
};

struct ClusterSeason {
  int tag_id = 0;
  /// The tag's pose on the cluster's last visit that saw it and gave it (that visit's world):
  /// where the season viewer draws the cluster.
  std::optional<Eigen::Isometry3d> T_world_tag;
  std::vector<std::size_t> tracks;  ///< indices into SeasonAnalysis::tracks
  std::size_t visits_with_tag = 0, visits_without_tag = 0;
  FruitSet fruit_set;
};

struct SeasonAnalysis {
  std::vector<double> days;           ///< the visits' days, in order
  std::vector<std::string> sources;   ///< the visits' files
  std::vector<FruitletTrack> tracks;  ///< by cluster, then in order of first sighting
  std::vector<ClusterSeason> clusters;
  double reference_mm_per_day = std::numeric_limits<double>::quiet_NaN();
  double threshold_mm_per_day = std::numeric_limits<double>::quiet_NaN();
  FruitSet fruit_set;  ///< of the whole sample (every cluster of every visit)
};

/// Follows each cluster's fruitlets across the visits (sorted by day; two on one day are
/// std::invalid_argument), fits each track's growth rate and predicts every fate with the
/// whole sample's reference rate.
SeasonAnalysis analyzeSeason(std::vector<SeasonVisit> visits, const SeasonConfig& config = {});

/// season.json (docs/season.md, "season.json").
nlohmann::json seasonJson(const SeasonAnalysis& season, const SeasonConfig& config);

}  // namespace fvp::host::season
