// OctoMap's probabilistic occupancy model (docs/design.md section 5), shared by both map
// engines so they agree voxel for voxel.
#pragma once

#include <cmath>
#include <string>

namespace fvp::host::map {

inline constexpr double kDefaultProbHit = 0.7;
inline constexpr double kDefaultProbMiss = 0.4;
inline constexpr double kDefaultClampMin = 0.12;
inline constexpr double kDefaultClampMax = 0.97;
inline constexpr double kDefaultOccupiedProb = 0.5;  ///< occupied when p > this

struct OccupancyModel {
  double prob_hit = kDefaultProbHit;
  double prob_miss = kDefaultProbMiss;
  double clamp_min = kDefaultClampMin;
  double clamp_max = kDefaultClampMax;
  double occupied_prob = kDefaultOccupiedProb;

  static float logOdds(double p) { return static_cast<float>(std::log(p / (1.0 - p))); }
  float hitLogOdds() const { return logOdds(prob_hit); }
  float missLogOdds() const { return logOdds(prob_miss); }
  float clampMinLogOdds() const { return logOdds(clamp_min); }
  float clampMaxLogOdds() const { return logOdds(clamp_max); }
  float occupiedLogOdds() const { return logOdds(occupied_prob); }
  /// Throws std::invalid_argument naming the field (`source`.prob_hit, ...) when out of range.
  void validate(const std::string& source = "occupancy model") const;
};

}  // namespace fvp::host::map
