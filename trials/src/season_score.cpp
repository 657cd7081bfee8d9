#include "fvp/trials/season_score.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace fvp::trials {
namespace {

using host::season::Fate;
using host::season::FruitletTrack;
using host::season::GrowthRate;
using host::season::SizeOnDay;
using host::season::TrackedSize;
using robot::sim::GrowthCurve;
using robot::sim::World;

// The result's truth centres are the world's, through JSON's round trip.
constexpr double kSameCentreM = 1e-9;

/// A result's clusters as the season's reader takes them: (tag id, the cluster's object).
std::vector<std::pair<int, const nlohmann::json*>> clusterEntries(const nlohmann::json& result) {
  std::vector<std::pair<int, const nlohmann::json*>> out;
  const auto clusters = result.find("clusters");
  if (clusters == result.end() || !clusters->is_array()) {
    out.emplace_back(result.value("tag_id", 0), &result);
    return out;
  }
  for (const auto& c : *clusters)
    if (c.is_object() && (c.contains("sized_fruitlets") || c.contains("T_world_tag")))
      out.emplace_back(c.value("tag_id", 0), &c);
  return out;
}

/// Which true fruitlet each detection of a visit is, by the result's own matching (its truth
/// entries' "detection") and the world's centres.
struct VisitTruth {
  std::map<std::pair<int, std::size_t>, int> identity_of_detection;  ///< (tag, detection)
  std::set<int> matched;
};

VisitTruth visitTruth(const nlohmann::json& result, const World& world) {
  VisitTruth truth;
  for (const auto& [tag, cluster] : clusterEntries(result)) {
    // A cluster whose tag was not seen is not read into the season (season_visit.h).
    if (!cluster->contains("T_world_tag")) continue;
    const auto fruitlets = cluster->find("fruitlets");
    if (fruitlets == cluster->end() || !fruitlets->is_array()) continue;
    for (const auto& f : *fruitlets) {
      if (!f.value("matched", false) || !f.contains("detection")) continue;
      const auto& g = f.at("gt_center_m");
      const Eigen::Vector3d centre(g.at(0).get<double>(), g.at(1).get<double>(),
                                   g.at(2).get<double>());
      int identity = -1;
      for (const robot::sim::Fruitlet& w : world.fruitlets())
        if ((w.center_m - centre).norm() < kSameCentreM) identity = w.identity;
      if (identity < 0)
        throw std::invalid_argument(
            "scoreSeason: a matched fruitlet of a visit's result is not in its world (another "
            "seed, day or world config?)");
      truth.identity_of_detection[{tag, f.at("detection").get<std::size_t>()}] = identity;
      truth.matched.insert(identity);
    }
  }
  return truth;
}

struct Scoring {
  const SeasonScoreInput& in;
  const host::season::SeasonAnalysis& analysis;
  const std::vector<GrowthCurve>& curves;
  std::vector<VisitTruth> visits;
  std::map<int, double> day0_size_mm;  ///< by identity

  int identityOf(const FruitletTrack& t, const TrackedSize& s) const {
    const auto& ids = visits.at(s.visit).identity_of_detection;
    const auto it = ids.find({t.tag_id, s.index_in_visit});
    return it == ids.end() ? -1 : it->second;
  }
  double truthSizeMm(int identity, double day) const {
    return day0_size_mm.at(identity) + curves.at(identity).grownMm(day);
  }
  double lastDay() const { return analysis.days.back(); }
};

double percent(std::size_t part, std::size_t whole) {
  return whole > 0 ? 100.0 * double(part) / double(whole) : std::nan("");
}
nlohmann::json numberOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

/// Links the tracks made (one size to the next) against the truth's (a fruitlet's consecutive
/// sightings). A link with a spurious end (a detection of no fruitlet) is a detection's error,
/// not the association's: counted apart, outside correct_percent.
nlohmann::json associationScore(const Scoring& s) {
  std::size_t made = 0, correct = 0, with_spurious = 0, truth_links = 0, found = 0;
  std::set<std::tuple<int, std::size_t, std::size_t>> correct_links;
  for (const FruitletTrack& t : s.analysis.tracks)
    for (std::size_t k = 1; k < t.sizes.size(); ++k) {
      const int a = s.identityOf(t, t.sizes[k - 1]), b = s.identityOf(t, t.sizes[k]);
      if (a < 0 || b < 0) {
        ++with_spurious;
        continue;
      }
      ++made;
      if (a != b) continue;
      ++correct;
      correct_links.insert({a, t.sizes[k - 1].visit, t.sizes[k].visit});
    }
  std::map<int, std::vector<std::size_t>> sightings;
  for (std::size_t v = 0; v < s.visits.size(); ++v)
    for (const int id : s.visits[v].matched) sightings[id].push_back(v);
  for (const auto& [id, seen] : sightings)
    for (std::size_t k = 1; k < seen.size(); ++k) {
      ++truth_links;
      found += correct_links.count({id, seen[k - 1], seen[k]});
    }
  return {{"links_made", made},
          {"links_correct", correct},
          {"links_with_spurious", with_spurious},
          {"truth_links", truth_links},
          {"truth_links_found", found},
          {"correct_percent", numberOrNull(percent(correct, made))},
          {"found_percent", numberOrNull(percent(found, truth_links))}};
}

/// Per identity, the track holding most of its sightings (the later on a tie).
std::map<int, std::size_t> trackOfIdentity(const Scoring& s) {
  std::map<int, std::map<std::size_t, std::size_t>> counts;
  for (std::size_t t = 0; t < s.analysis.tracks.size(); ++t)
    for (const TrackedSize& size : s.analysis.tracks[t].sizes)
      if (const int id = s.identityOf(s.analysis.tracks[t], size); id >= 0) ++counts[id][t];
  std::map<int, std::size_t> out;
  for (const auto& [id, by_track] : counts) {
    std::size_t best = 0, most = 0;
    for (const auto& [t, n] : by_track)
      if (n >= most) best = t, most = n;
    out[id] = best;
  }
  return out;
}

/// Fallen fruitlets (sized at least once, off the tree by the last visit) and whether their
/// track says gone; tracks gone whose fruitlet is still on the tree.
nlohmann::json goneScore(const Scoring& s, const std::map<int, std::size_t>& track_of) {
  std::size_t fallen = 0, reported = 0, wrongly_gone = 0;
  for (const auto& [id, t] : track_of) {
    if (s.curves.at(id).onTree(s.lastDay())) continue;
    ++fallen;
    reported += s.analysis.tracks[t].gone;
  }
  for (const FruitletTrack& t : s.analysis.tracks) {
    const int id = t.gone ? s.identityOf(t, t.sizes.back()) : -1;
    wrongly_gone += id >= 0 && s.curves.at(id).onTree(s.lastDay());
  }
  return {{"fallen_sized", fallen},
          {"reported_gone", reported},
          {"reported_percent", numberOrNull(percent(reported, fallen))},
          {"wrongly_gone", wrongly_gone}};
}

/// A track's sizes for the summary's pooled floor fit: one entry each, with the track's
/// place in the analysis, both sizes (robot's, truth's), the stated error and its images.
void addSizeRecords(const FruitletTrack& t, std::size_t track, int identity,
                    const std::vector<SizeOnDay>& truth, nlohmann::json& records) {
  for (std::size_t k = 0; k < truth.size(); ++k)
    records.push_back({{"track", track},
                       {"identity", identity},
                       {"day", truth[k].day},
                       {"size_mm", t.sizes[k].sized.at.size_mm},
                       {"truth_mm", truth[k].size_mm},
                       {"standard_error_mm", numberOrNull(t.sizes[k].sized.standard_error_mm)},
                       {"well_seen_images", t.sizes[k].sized.well_seen_images}});
}

/// A track's size errors as a rate sees them (a bias every visit shares cancels in a slope),
/// over tracks whose every size states a standard error: each error's squared deviation from
/// the track's mean error, with sizes - 1 degrees of freedom a track, and the squared stated
/// errors weighted (n - 1) / n each, so that both estimate the same variance.
struct SizeErrorSpread {
  double deviation_ss_mm2 = 0.0, stated_ss_mm2 = 0.0;
  std::size_t dof = 0;
  std::vector<std::vector<SizeError>> tracks;  ///< for the floor's fit
  void add(const FruitletTrack& t, const std::vector<SizeOnDay>& truth) {
    const double n = double(truth.size());
    std::vector<SizeError> errors;
    double mean_error_mm = 0.0, stated_mm2 = 0.0;
    for (std::size_t k = 0; k < truth.size(); ++k) {
      const double se_mm = t.sizes[k].sized.standard_error_mm;
      if (!std::isfinite(se_mm)) return;
      errors.push_back({t.sizes[k].sized.at.size_mm - truth[k].size_mm, se_mm});
      mean_error_mm += errors.back().error_mm / n;
      stated_mm2 += se_mm * se_mm * (n - 1.0) / n;
    }
    for (const SizeError& e : errors)
      deviation_ss_mm2 += (e.error_mm - mean_error_mm) * (e.error_mm - mean_error_mm);
    stated_ss_mm2 += stated_mm2;
    dof += truth.size() - 1;
    tracks.push_back(std::move(errors));
  }
};

/// Each track of one fruitlet with a rate, against the truth's rate over the same days.
nlohmann::json growthScore(const Scoring& s) {
  std::size_t scored = 0, with_error = 0, covered = 0;
  double abs_sum = 0.0, worst = 0.0;
  SizeErrorSpread spread;
  nlohmann::json records = nlohmann::json::array();
  for (std::size_t index = 0; index < s.analysis.tracks.size(); ++index) {
    const FruitletTrack& t = s.analysis.tracks[index];
    if (!std::isfinite(t.rate.mm_per_day)) continue;
    const int id = s.identityOf(t, t.sizes.front());
    bool one_fruitlet = id >= 0;
    std::vector<SizeOnDay> truth;
    for (const TrackedSize& size : t.sizes) {
      one_fruitlet = one_fruitlet && s.identityOf(t, size) == id;
      if (one_fruitlet) truth.push_back({size.day, s.truthSizeMm(id, size.day)});
    }
    if (!one_fruitlet) continue;
    spread.add(t, truth);
    addSizeRecords(t, index, id, truth, records);
    const double error = t.rate.mm_per_day - host::season::fitGrowthRate(truth).mm_per_day;
    ++scored;
    abs_sum += std::abs(error);
    worst = std::max(worst, std::abs(error));
    if (std::isfinite(t.rate.standard_error_mm_per_day)) {
      ++with_error;
      covered +=
          std::abs(error) <= host::season::rateIntervalHalfWidth(0.95, t.rate.degrees_of_freedom) *
                                 t.rate.standard_error_mm_per_day;
    }
  }
  return {{"tracks_scored", scored},
          {"mae_mm_per_day", numberOrNull(scored ? abs_sum / double(scored) : std::nan(""))},
          {"worst_mm_per_day", numberOrNull(scored ? worst : std::nan(""))},
          {"with_standard_error", with_error},
          {"covered_95", covered},
          {"covered_95_percent", numberOrNull(percent(covered, with_error))},
          {"size_deviation_ss_mm2", spread.deviation_ss_mm2},
          {"size_deviation_dof", spread.dof},
          {"stated_standard_error_ss_mm2", spread.stated_ss_mm2},
          {"size_error_floor_fit_mm", numberOrNull(sizeErrorFloorFit(spread.tracks))},
          {"sizes", records}};
}

/// Confusion of "drops" (positive) over every fruitlet on the tree on the first visit; an
/// undecided one (unsized, or no fate) counts as wrong either way.
struct Confusion {
  std::size_t tp = 0, fp = 0, fn = 0, tn = 0, undecided = 0;
  void add(bool truth_drops, std::optional<bool> predicted_drops) {
    if (!predicted_drops) {
      ++undecided;
      ++(truth_drops ? fn : fp);
      return;
    }
    if (*predicted_drops)
      ++(truth_drops ? tp : fp);
    else
      ++(truth_drops ? fn : tn);
  }
  nlohmann::json json() const {
    return {{"true_drops", tp},       {"false_drops", fp},
            {"missed_drops", fn},     {"true_stays", tn},
            {"undecided", undecided}, {"f1_drops", dropsF1(double(tp), double(fp), double(fn))}};
  }
};

std::optional<bool> dropsOf(const FruitletTrack& t) {
  if (t.unconfirmed) return std::nullopt;
  if (t.gone) return true;
  if (t.fate.fate == Fate::kUnknown) return std::nullopt;
  return t.fate.fate == Fate::kAbscises;
}

/// A standard normal variate from raw engine bits (Box-Muller): the same draws with any
/// standard library (std::normal_distribution's are implementation-defined).
double standardNormal(std::mt19937_64& rng) {
  const double u1 = (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53;
  const double u2 = static_cast<double>(rng() >> 11) * 0x1.0p-53;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

/// The person with calipers: every fruitlet on the tree read on every visit (one reading, its
/// error kCaliperSigmaMm), one already off noted as dropped; the same growth-rate rule.
struct CaliperOutcome {
  std::map<int, std::optional<bool>> drops;  ///< by identity
  double fruit_set_percent = std::nan("");
};

CaliperOutcome caliperBaseline(const Scoring& s, const std::vector<int>& identities) {
  std::mt19937_64 rng(s.in.caliper_seed);
  std::vector<GrowthRate> rates;
  std::vector<bool> gone;
  for (const int id : identities) {
    std::vector<SizeOnDay> readings;
    for (const double day : s.analysis.days)
      if (s.curves.at(id).onTree(day))
        readings.push_back({day,
                            s.truthSizeMm(id, day) + s.in.caliper_sigma_mm * standardNormal(rng),
                            s.in.caliper_sigma_mm});
    gone.push_back(!s.curves.at(id).onTree(s.lastDay()));
    rates.push_back(gone.back() ? GrowthRate{} : host::season::fitGrowthRate(readings));
  }
  const host::season::FruitSetPrediction p = host::season::predictFruitSet(rates, s.in.fate);
  CaliperOutcome out;
  double expected = 0.0;
  std::size_t counted = 0;
  for (std::size_t i = 0; i < identities.size(); ++i) {
    if (gone[i]) {
      out.drops[identities[i]] = true;
      ++counted;
    } else if (p.fates[i].fate == Fate::kUnknown) {
      out.drops[identities[i]] = std::nullopt;
    } else {
      out.drops[identities[i]] = p.fates[i].fate == Fate::kAbscises;
      expected += p.fates[i].persist_probability;
      ++counted;
    }
  }
  if (counted > 0) out.fruit_set_percent = 100.0 * expected / double(counted);
  return out;
}

}  // namespace

namespace {

/// Sum over tracks of sum w (e - e_w)^2 with w = 1 / (se^2 + f^2).
double weightedSpread(const std::vector<std::vector<SizeError>>& tracks, double floor_mm) {
  double q = 0.0;
  for (const auto& track : tracks) {
    double w_sum = 0.0, we_sum = 0.0;
    for (const SizeError& e : track) {
      const double w = 1.0 / (e.standard_error_mm * e.standard_error_mm + floor_mm * floor_mm);
      w_sum += w;
      we_sum += w * e.error_mm;
    }
    const double mean_mm = we_sum / w_sum;
    for (const SizeError& e : track) {
      const double w = 1.0 / (e.standard_error_mm * e.standard_error_mm + floor_mm * floor_mm);
      q += w * (e.error_mm - mean_mm) * (e.error_mm - mean_mm);
    }
  }
  return q;
}

}  // namespace

double sizeErrorFloorFit(const std::vector<std::vector<SizeError>>& tracks) {
  double dof = 0.0, largest_deviation_mm = 0.0;
  for (const auto& track : tracks) {
    for (const SizeError& e : track)
      if (!(e.standard_error_mm >= host::season::kMinStandardErrorMm &&
            e.standard_error_mm <= host::season::kMaxStandardErrorMm) ||
          !(std::abs(e.error_mm) <= host::season::kMaxStandardErrorMm))
        throw std::invalid_argument(
            "sizeErrorFloorFit: every size needs an error within 1000 mm and a standard error "
            "from 1e-6 to 1000 mm");
    if (track.size() < 2) continue;
    dof += double(track.size() - 1);
    for (const SizeError& a : track)
      for (const SizeError& b : track)
        largest_deviation_mm = std::max(largest_deviation_mm, std::abs(a.error_mm - b.error_mm));
  }
  if (dof == 0.0) return std::nan("");
  if (weightedSpread(tracks, 0.0) <= dof) return 0.0;
  // The spread falls as f grows; at twice the largest deviation D a track's is below
  // n D^2 / (2 D)^2 = n / 4 <= n - 1, so the root lies between 0 and that.
  double low = 0.0, high = 2.0 * std::max(largest_deviation_mm, 1e-6);
  for (int i = 0; i < 200 && high - low > 1e-9; ++i) {
    const double mid = 0.5 * (low + high);
    (weightedSpread(tracks, mid) > dof ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

double dropsF1(double true_drops, double false_drops, double missed_drops) {
  const double denominator = 2.0 * true_drops + false_drops + missed_drops;
  return denominator > 0 ? 2.0 * true_drops / denominator : 1.0;
}

nlohmann::json scoreSeason(const SeasonScoreInput& in) {
  if (!in.analysis || in.visit_results.size() != in.analysis->days.size() ||
      in.visit_worlds.size() != in.analysis->days.size() || in.analysis->days.empty())
    throw std::invalid_argument("scoreSeason: expected one result and one world per visit");
  const World& first = *in.visit_worlds.front();
  Scoring s{in, *in.analysis, first.seasonGrowth().fruitlets, {}, {}};
  for (std::size_t v = 0; v < in.visit_worlds.size(); ++v) {
    const World& world = *in.visit_worlds[v];
    if (world.config().season_day != in.analysis->days[v])
      throw std::invalid_argument("scoreSeason: visit " + std::to_string(v) +
                                  "'s world is not of the visit's day");
    s.visits.push_back(visitTruth(*in.visit_results[v], world));
    for (const robot::sim::Fruitlet& f : world.fruitlets())
      s.day0_size_mm[f.identity] =
          f.gtSizeMm() - s.curves.at(f.identity).grownMm(world.config().season_day);
  }
  const std::map<int, std::size_t> track_of = trackOfIdentity(s);
  std::vector<int> identities;  // on the tree on the first visit
  for (const robot::sim::Fruitlet& f : first.fruitlets()) identities.push_back(f.identity);
  const CaliperOutcome calipers = caliperBaseline(s, identities);
  Confusion robot_fates, caliper_fates;
  std::size_t persisting = 0, unsized = 0;
  for (const int id : identities) {
    const bool truth_drops = s.curves.at(id).abscises;
    persisting += !truth_drops;
    const auto t = track_of.find(id);
    unsized += t == track_of.end();
    robot_fates.add(truth_drops,
                    t == track_of.end() ? std::nullopt : dropsOf(in.analysis->tracks[t->second]));
    caliper_fates.add(truth_drops, calipers.drops.at(id));
  }
  nlohmann::json robot = robot_fates.json();
  robot["unsized"] = unsized;
  return {{"fruitlets", identities.size()},
          {"association", associationScore(s)},
          {"gone", goneScore(s, track_of)},
          {"growth", growthScore(s)},
          {"fate", {{"robot", robot}, {"calipers", caliper_fates.json()}}},
          {"fruit_set_percent",
           {{"truth", numberOrNull(percent(persisting, identities.size()))},
            {"robot", numberOrNull(in.analysis->fruit_set.percent)},
            {"calipers", numberOrNull(calipers.fruit_set_percent)}}},
          {"caliper_sigma_mm", in.caliper_sigma_mm}};
}

}  // namespace fvp::trials
