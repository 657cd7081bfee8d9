#include "fvp/robot/sim/season_growth.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "fvp/robot/sim/world.h"
#include "procedural_texture.h"
#include "sampler.h"

namespace fvp::robot::sim {
namespace {

// "sesn" in ASCII: the season's stream, apart from the generator's.
constexpr std::uint64_t kSeasonStream = 0x7365736e;

}  // namespace

double GrowthCurve::grownMm(double day) const {
  return rate_mm_per_day * std::clamp(day, 0.0, stops_growing_day);
}

SeasonGrowth drawSeasonGrowth(const World& day0, std::uint64_t seed) {
  const WorldConfig& config = day0.config();
  // The generator's sampler on the season's own stream.
  detail::Sampler rng(detail::hashCombine(seed, kSeasonStream));
  SeasonGrowth season;
  season.fastest_mm_per_day =
      rng.uniform(config.min_fastest_growth_mm_per_day, config.max_fastest_growth_mm_per_day);
  season.fruitlets.resize(day0.fruitlets().size());
  for (const FruitletCluster& cluster : day0.clusters()) {
    int king = -1;
    for (int i : cluster.fruitlet_indices)
      if (king < 0 || day0.fruitlets()[i].radius_m > day0.fruitlets()[king].radius_m) king = i;
    for (int i : cluster.fruitlet_indices) {
      GrowthCurve& curve = season.fruitlets[i];
      curve.identity = i;
      curve.cluster = cluster.index;
      curve.king = i == king;
      // Every draw is made for every fruitlet, so one fruitlet's fate never shifts another's.
      const double drop_draw = rng.uniform();
      const double share_draw = rng.uniform();
      const double stop_day = rng.uniform(kMinStopsGrowingDay, kMaxStopsGrowingDay);
      const double fall_day = rng.uniform(kMinFallsOffDay, kMaxFallsOffDay);
      curve.abscises = !curve.king && drop_draw < config.abscission_probability;
      if (curve.abscises) {
        curve.rate_mm_per_day = season.fastest_mm_per_day * kMaxAbscisingShare * share_draw;
        curve.stops_growing_day = stop_day;
        curve.falls_off_day = std::max(stop_day, fall_day);
      } else {
        const double lo = curve.king ? kMinKingShare : kMinPersistingShare;
        curve.rate_mm_per_day = season.fastest_mm_per_day * (lo + (1.0 - lo) * share_draw);
      }
    }
  }
  season.leaves.resize(day0.leaves().size());
  for (LeafGrowth& leaf : season.leaves) {
    leaf.turn_axis = rng.unitVector();
    leaf.turn_deg_per_day = rng.uniform(-1.0, 1.0) * kMaxLeafTurnDegPerDay;
  }
  return season;
}

std::uint64_t visitSeed(std::uint64_t world_seed, double day) {
  if (day == 0.0) return world_seed;
  return detail::hashCombine(detail::hashCombine(world_seed, kSeasonStream),
                             std::bit_cast<std::uint64_t>(day));
}

}  // namespace fvp::robot::sim
