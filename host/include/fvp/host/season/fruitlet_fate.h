// The thinning decision a season's growth rates feed (docs/season.md): the fruitlet growth-rate
// model (Greene et al. 2013; the Predicting Fruitset spreadsheet of Schwallier and
// Irish-Brown, Michigan State University): a fruitlet growing at less than half the rate of
// the sample's fastest-growing fruitlets is predicted to drop; the share predicted to stay is
// the predicted fruit set.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "fvp/host/season/growth_rate.h"

namespace fvp::host::season {

enum class Fate {
  kPersists,  ///< growing at least abscission_ratio times the fastest fruitlets' rate
  kAbscises,  ///< growing slower: predicted to drop
  kUnknown    ///< no rate (sized on one day only), or no fruitlet of the sample grows
};

const char* toString(Fate fate);

struct FateConfig {
  /// A fruitlet growing at less than this share of the reference rate is predicted to drop
  /// (the model's 50 %).
  double abscission_ratio = 0.5;
  /// The reference rate: the mean rate of this share of the sample's fruitlets, the fastest
  /// (at least one fruitlet). The model compares with "the fastest-growing fruitlets"; the
  /// share is ours (docs/season.md).
  double fastest_share = 0.2;
  /// Throws std::invalid_argument naming the field: a ratio or share outside (0, 1].
  void validate() const;
};

struct FatePrediction {
  Fate fate = Fate::kUnknown;
  /// The probability that the fruitlet's true rate reaches the threshold, from its rate's
  /// standard error (normal); 1 or 0 where the rate has none; NaN for kUnknown.
  double persist_probability = std::numeric_limits<double>::quiet_NaN();
};

struct FruitSetPrediction {
  double reference_mm_per_day = std::numeric_limits<double>::quiet_NaN();
  double threshold_mm_per_day = std::numeric_limits<double>::quiet_NaN();
  std::vector<FatePrediction> fates;  ///< one per rate, in order
  std::size_t persisting = 0, abscising = 0, unknown = 0;
  /// The expected share persisting among the fruitlets with a fate (the mean of their persist
  /// probabilities), and its standard error (the spread of that sum of Bernoulli outcomes).
  double fruit_set_percent = std::numeric_limits<double>::quiet_NaN();
  double fruit_set_standard_error_percent = std::numeric_limits<double>::quiet_NaN();
};

/// Each fruitlet's predicted fate and the sample's predicted fruit set. A fruitlet known to
/// have dropped already is the caller's to count as abscised (its rate is not defined).
FruitSetPrediction predictFruitSet(const std::vector<GrowthRate>& rates,
                                   const FateConfig& config = {});

}  // namespace fvp::host::season
