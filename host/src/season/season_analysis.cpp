#include "fvp/host/season/season_analysis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

namespace fvp::host::season {

void SeasonConfig::validate() const {
  association.validate();
  fate.validate();
  if (!(size_error_floor_mm >= 0.0 && size_error_floor_mm <= kMaxStandardErrorMm))
    throw std::invalid_argument("SeasonConfig: size_error_floor_mm must lie in [0, 1000] mm, got " +
                                std::to_string(size_error_floor_mm));
}

namespace {

/// Tracks sized on one visit after the cluster's first that searched it, and gone since (a
/// later visit searched and did not find them): a fruitlet that appeared after the first visit
/// and was gone by the last. Visits cut short judge neither.
void markUnconfirmed(const ClusterSeason& cluster, const std::vector<SeasonVisit>& visits,
                     std::vector<FruitletTrack>& tracks) {
  std::vector<std::size_t> searched;  // the visits that saw the cluster's tag and searched it
  for (std::size_t v = 0; v < visits.size(); ++v)
    for (const VisitCluster& c : visits[v].clusters)
      if (c.tag_id == cluster.tag_id && c.tag_seen && c.searched) searched.push_back(v);
  for (const std::size_t t : cluster.tracks) {
    FruitletTrack& track = tracks[t];
    const std::size_t v = track.sizes.front().visit;
    if (track.sizes.size() == 1 && !searched.empty() && v > searched.front() && track.gone) {
      track.unconfirmed = true;
      track.gone = false;
    }
  }
}

/// Follows one cluster's fruitlets over the visits: each visit that saw the tag is associated
/// with the last size of every track so far (tracks missed once stay, to be found again); the
/// unpaired fruitlets start tracks; a track not found on the cluster's latest visit that searched
/// it (VisitCluster::searched) is gone.
void followCluster(int tag_id, const std::vector<SeasonVisit>& visits,
                   const AssociationConfig& config, SeasonAnalysis& out) {
  ClusterSeason cluster;
  cluster.tag_id = tag_id;
  for (std::size_t v = 0; v < visits.size(); ++v)
    for (const VisitCluster& c : visits[v].clusters) {
      if (c.tag_id != tag_id) continue;
      if (!c.tag_seen) {
        ++cluster.visits_without_tag;
        continue;
      }
      ++cluster.visits_with_tag;
      if (c.T_world_tag) cluster.T_world_tag = c.T_world_tag;
      std::vector<VisitFruitlet> earlier, later;
      std::vector<double> days_since;  // each track's growth gate: since its own last size
      for (const std::size_t t : cluster.tracks) {
        earlier.push_back(out.tracks[t].sizes.back().sized.at);
        days_since.push_back(visits[v].day - out.tracks[t].sizes.back().day);
      }
      for (const SizedFruitlet& f : c.fruitlets) later.push_back(f.at);
      const Association a = associateFruitlets(earlier, later, days_since, config);
      const std::vector<std::size_t> before = cluster.tracks;
      for (std::size_t e = 0; e < before.size(); ++e) {
        FruitletTrack& track = out.tracks[before[e]];
        const int l = a.later_of_earlier[e];
        // Not found by a visit cut short: missed there, as the visit before left it.
        if (l >= 0 || c.searched) track.gone = l < 0;
        if (l >= 0)
          track.sizes.push_back(
              {v, visits[v].day, c.fruitlets[std::size_t(l)], a.confidence[e], std::size_t(l)});
      }
      for (std::size_t l = 0; l < later.size(); ++l) {
        if (a.earlier_of_later[l] >= 0) continue;
        FruitletTrack track;
        track.tag_id = tag_id;
        track.sizes.push_back(
            {v, visits[v].day, c.fruitlets[l], std::numeric_limits<double>::quiet_NaN(), l});
        cluster.tracks.push_back(out.tracks.size());
        out.tracks.push_back(std::move(track));
      }
    }
  markUnconfirmed(cluster, visits, out.tracks);
  out.clusters.push_back(std::move(cluster));
}

/// The expected share set among the tracks with a fate or gone (gone: dropped).
FruitSet fruitSetOf(const std::vector<FruitletTrack>& tracks,
                    const std::vector<std::size_t>& indices) {
  FruitSet set;
  double expected = 0.0, variance = 0.0;
  for (const std::size_t i : indices) {
    const FruitletTrack& t = tracks[i];
    if (t.unconfirmed) {
      ++set.unconfirmed;
      continue;
    }
    if (t.gone) {
      ++set.gone;
      continue;
    }
    if (t.fate.fate == Fate::kUnknown) {
      ++set.unknown;
      continue;
    }
    ++(t.fate.fate == Fate::kPersists ? set.persisting : set.abscising);
    expected += t.fate.persist_probability;
    variance += t.fate.persist_probability * (1.0 - t.fate.persist_probability);
  }
  const std::size_t counted = set.persisting + set.abscising + set.gone;
  if (counted > 0) {
    set.percent = 100.0 * expected / double(counted);
    set.standard_error_percent = 100.0 * std::sqrt(variance) / double(counted);
  }
  return set;
}

/// Every track's rate, and every fate against the whole sample's reference (gone tracks
/// neither set the reference nor get a fate).
void predictFates(SeasonAnalysis& out, const SeasonConfig& config) {
  std::vector<GrowthRate> rates;
  for (FruitletTrack& t : out.tracks) {
    std::vector<SizeOnDay> sizes;
    for (const TrackedSize& s : t.sizes)  // NaN (unknown) stays NaN
      sizes.push_back({s.day, s.sized.at.size_mm,
                       std::hypot(s.sized.standard_error_mm, config.size_error_floor_mm)});
    t.rate = fitGrowthRate(sizes);
    rates.push_back(t.gone ? GrowthRate{} : t.rate);
  }
  const FruitSetPrediction prediction = predictFruitSet(rates, config.fate);
  out.reference_mm_per_day = prediction.reference_mm_per_day;
  out.threshold_mm_per_day = prediction.threshold_mm_per_day;
  std::vector<std::size_t> all;
  for (std::size_t i = 0; i < out.tracks.size(); ++i) {
    out.tracks[i].fate = prediction.fates[i];
    all.push_back(i);
  }
  out.fruit_set = fruitSetOf(out.tracks, all);
  for (ClusterSeason& c : out.clusters) c.fruit_set = fruitSetOf(out.tracks, c.tracks);
}

}  // namespace

SeasonAnalysis analyzeSeason(std::vector<SeasonVisit> visits, const SeasonConfig& config) {
  config.validate();
  for (const SeasonVisit& visit : visits)  // before sorting: NaN has no order
    if (!std::isfinite(visit.day))
      throw std::invalid_argument("analyzeSeason: " + visit.source + ": day is not finite");
  std::stable_sort(visits.begin(), visits.end(),
                   [](const SeasonVisit& a, const SeasonVisit& b) { return a.day < b.day; });
  SeasonAnalysis out;
  std::set<int> tags;
  for (std::size_t v = 0; v < visits.size(); ++v) {
    if (v > 0 && visits[v].day == visits[v - 1].day)
      throw std::invalid_argument("analyzeSeason: two visits on day " +
                                  std::to_string(visits[v].day) + ": " + visits[v - 1].source +
                                  " and " + visits[v].source);
    out.days.push_back(visits[v].day);
    out.sources.push_back(visits[v].source);
    for (const VisitCluster& c : visits[v].clusters) tags.insert(c.tag_id);
  }
  for (const int tag : tags) followCluster(tag, visits, config.association, out);
  predictFates(out, config);
  return out;
}

}  // namespace fvp::host::season
