// A simulated season's analysis scored against the world's truth (docs/season.md "Simulated
// seasons"): were the visits' fruitlets followed correctly, were the fallen ones reported
// gone, how close are the growth rates, fates and fruit set; and the same decision from a
// simulated person with calipers measuring the same fruitlets on the same days.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "fvp/host/season/season_analysis.h"
#include "fvp/robot/sim/world.h"

namespace fvp::trials {

/// The caliper baseline's reading error (standard deviation of one reading of a fruitlet's
/// diameter), mm: a digital caliper reads to 0.01 mm (±0.02 mm rated), but where a person
/// closes the jaws on a small, soft, not quite round fruitlet, and how hard, moves a reading
/// by a few tenths; docs/season.md "The caliper baseline" states the assumption.
inline constexpr double kCaliperSigmaMm = 0.2;

struct SeasonScoreInput {
  const host::season::SeasonAnalysis* analysis = nullptr;
  /// Each visit's result.json object, in the analysis' day order.
  std::vector<const nlohmann::json*> visit_results;
  /// Each visit's world (the same seed, grown to that day), in the same order.
  std::vector<const robot::sim::World*> visit_worlds;
  double caliper_sigma_mm = kCaliperSigmaMm;
  std::uint64_t caliper_seed = 1;
  host::season::FateConfig fate;  ///< the rule the calipers' readings are judged by
};

/// F1 of "drops" from its confusion counts (1 when there is nothing to find and nothing
/// found): one season's and the pooled seasons'.
double dropsF1(double true_drops, double false_drops, double missed_drops);

/// One size of a track as the floor's fit sees it: its error against the truth and its stated
/// standard error.
struct SizeError {
  double error_mm = 0.0;
  double standard_error_mm = 0.0;
};

/// The floor f (mm) that, added in quadrature to every stated standard error, makes the
/// tracks' weighted spread about their own mean errors what those errors say
/// (sum over tracks of sum w (e - e_w)^2 = sum (n - 1), w = 1 / (se^2 + f^2): the Paule-Mandel
/// moment equation, one shared excess variance); 0 when the stated errors already account for
/// the spread, NaN without any track of two sizes. A bias a track's sizes share cancels.
double sizeErrorFloorFit(const std::vector<std::vector<SizeError>>& tracks);

/// The score object (docs/season.md "season_score.json"): association (links made, correct,
/// truth links), gone (fallen fruitlets reported gone, tracks wrongly gone), growth (rate MAE
/// against the truth's rate over the same days, and how often the stated uncertainty covers
/// it), fate (confusion and F1 of "drops" for the robot and the calipers) and fruit set (truth,
/// robot, calipers, in percent). Throws std::invalid_argument when the inputs disagree (a
/// visit without its world, a day the analysis lacks).
nlohmann::json scoreSeason(const SeasonScoreInput& input);

}  // namespace fvp::trials
