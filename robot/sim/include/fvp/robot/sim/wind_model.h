// Wind between views (docs/simulation.md "Wind"): each view sees the canopy in another pose.
// Every leaf turns about its attachment (its stalk end) by a small random angle, so its tip
// moves by ~wind_leaf_tip_m; every fruitlet swings on its stem, horizontally, by up to
// wind_fruitlet_swing_m. Moves that would bring a fruitlet into another fruitlet or a leaf
// into a fruitlet are shortened (halved, then dropped). Ground truth stays the rest pose, as a
// grower's calipers measure the fruitlet, not where it hung during a view. Deterministic per
// (seed, view); all zero by default.
#pragma once

#include <cstdint>

#include "fvp/robot/sim/world.h"
#include "fvp/robot/sim/world_config.h"

namespace fvp::robot::sim {

class WindModel {
 public:
  /// Tip displacements are drawn N(0, wind_leaf_tip_m^2) and cut at this many sigma, so a
  /// leaf's tip never moves more than kMaxTipSigmas * wind_leaf_tip_m.
  static constexpr double kMaxTipSigmas = 2.0;
  /// A move that collides is halved this many times before it is dropped.
  static constexpr int kShortenings = 3;

  /// rest must outlive the model. The draws come from seed on a stream of their own.
  WindModel(const World& rest, std::uint64_t seed);

  bool enabled() const { return enabled_; }
  /// The world as view `view` sees it (the rest world when wind is off).
  World worldAt(int view) const;

 private:
  const World& rest_;
  std::uint64_t seed_ = 0;
  double tip_sigma_m_ = 0.0, swing_m_ = 0.0;
  bool enabled_ = false;
};

}  // namespace fvp::robot::sim
