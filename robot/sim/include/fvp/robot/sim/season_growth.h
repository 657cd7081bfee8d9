// How a simulated world grows over a season (docs/simulation.md "A season"): each fruitlet's
// growth curve and fate, each leaf's growth and turn, drawn once per world from a stream of
// their own so that the day-0 world is the one World::generate always gave. A visit on day d
// sees World::generate(config with season_day = d, seed): the same tree, grown.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

namespace fvp::robot::sim {

class World;

/// One fruitlet's season: its equatorial diameter grows at rate_mm_per_day until
/// stops_growing_day, and it falls off the tree on falls_off_day (both infinite for a
/// fruitlet that persists).
struct GrowthCurve {
  int identity = 0;  ///< the fruitlet's index on day 0: its name for the whole season
  int cluster = 0;
  bool king = false;      ///< its cluster's largest on day 0
  bool abscises = false;  ///< bound to drop (whether or not it has fallen by a given day)
  double rate_mm_per_day = 0.0;
  double stops_growing_day = std::numeric_limits<double>::infinity();
  double falls_off_day = std::numeric_limits<double>::infinity();
  /// Diameter gained by `day` (>= 0), millimetres.
  double grownMm(double day) const;
  bool onTree(double day) const { return day < falls_off_day; }
  /// The mean growth rate between two days (a < b), mm/day: what two caliper readings give.
  double meanRateMmPerDay(double a, double b) const { return (grownMm(b) - grownMm(a)) / (b - a); }
};

/// A leaf's season: it grows about its stalk and turns slowly about an axis through it.
struct LeafGrowth {
  Eigen::Vector3d turn_axis = Eigen::Vector3d::UnitZ();  ///< unit, world frame
  double turn_deg_per_day = 0.0;
};

struct SeasonGrowth {
  /// The diameter growth rate of this season's fastest-growing fruitlets (the weather's).
  double fastest_mm_per_day = 0.0;
  std::vector<GrowthCurve> fruitlets;  ///< by identity (day-0 index)
  std::vector<LeafGrowth> leaves;      ///< by leaf index
};

// The model's constants (docs/simulation.md "A season" gives their sources and reasoning).
/// A persisting fruitlet grows at this share of the fastest rate, uniformly; a king at the top.
inline constexpr double kMinPersistingShare = 0.7, kMinKingShare = 0.9;
/// An abscising fruitlet grows at up to this share of the fastest rate, then stops between
/// these days and falls off between those.
inline constexpr double kMaxAbscisingShare = 0.4;
inline constexpr double kMinStopsGrowingDay = 2.0, kMaxStopsGrowingDay = 5.0;
inline constexpr double kMinFallsOffDay = 5.0, kMaxFallsOffDay = 12.0;
/// A fruitlet's stem droops this far (metres) per millimetre its diameter gains.
inline constexpr double kStemDroopMPerMm = 0.0005;
/// Neighbouring fruitlets press into each other by up to this much (bounding spheres) before
/// they push each other apart.
inline constexpr double kMaxPressM = 0.001;
/// Leaves grow this share of their size a day, and turn at up to this rate.
inline constexpr double kLeafGrowthPerDay = 0.02;
inline constexpr double kMaxLeafTurnDegPerDay = 2.0;

/// The season of a day-0 world (World::generate's before any growth), drawn from the world
/// seed on the season's own stream.
SeasonGrowth drawSeasonGrowth(const World& day0, std::uint64_t seed);

/// The seed of what a visit on `day` draws anew (image noise, wind, light, pose and
/// segmentation errors): the world seed on day 0, another for every other day.
std::uint64_t visitSeed(std::uint64_t world_seed, double day);

}  // namespace fvp::robot::sim
