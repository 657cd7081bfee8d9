// season.json: the schema is docs/season.md's "season.json".
#include <cmath>

#include "fvp/host/season/season_analysis.h"

namespace fvp::host::season {
namespace {

using nlohmann::json;

/// A number, or null where it is not defined (NaN).
json numberOrNull(double v) {
  return std::isfinite(v) ? json(v) : json();
}

json fruitSetJson(const FruitSet& s) {
  return {{"percent", numberOrNull(s.percent)},
          {"standard_error_percent", numberOrNull(s.standard_error_percent)},
          {"persisting", s.persisting},
          {"abscising", s.abscising},
          {"gone", s.gone},
          {"unknown", s.unknown},
          {"unconfirmed", s.unconfirmed}};
}

json trackJson(const FruitletTrack& t, std::size_t id) {
  json sizes = json::array();
  for (const TrackedSize& s : t.sizes) {
    const Eigen::Vector3d& c = s.sized.at.center_tag_m;
    sizes.push_back({{"visit", s.visit},
                     {"day", s.day},
                     {"size_mm", s.sized.at.size_mm},
                     {"standard_error_mm", numberOrNull(s.sized.standard_error_mm)},
                     {"center_tag_m", {c.x(), c.y(), c.z()}},
                     {"association_confidence", numberOrNull(s.association_confidence)}});
  }
  return {{"id", id},
          {"sizes", sizes},
          {"growth_rate_mm_per_day", numberOrNull(t.rate.mm_per_day)},
          {"growth_rate_standard_error_mm_per_day", numberOrNull(t.rate.standard_error_mm_per_day)},
          {"growth_rate_degrees_of_freedom", numberOrNull(t.rate.degrees_of_freedom)},
          {"gone", t.gone},
          {"unconfirmed", t.unconfirmed},
          {"fate", t.unconfirmed ? "unconfirmed"
                   : t.gone      ? "gone"
                                 : toString(t.fate.fate)},
          {"persist_probability", t.gone ? json(0.0) : numberOrNull(t.fate.persist_probability)}};
}

}  // namespace

json seasonJson(const SeasonAnalysis& season, const SeasonConfig& config) {
  json visits = json::array();
  for (std::size_t v = 0; v < season.days.size(); ++v)
    visits.push_back({{"day", season.days[v]}, {"source", season.sources[v]}});
  json clusters = json::array();
  for (const ClusterSeason& c : season.clusters) {
    json fruitlets = json::array();
    for (std::size_t k = 0; k < c.tracks.size(); ++k)
      fruitlets.push_back(trackJson(season.tracks[c.tracks[k]], k));
    clusters.push_back({{"tag_id", c.tag_id},
                        {"visits_with_tag", c.visits_with_tag},
                        {"visits_without_tag", c.visits_without_tag},
                        {"fruit_set", fruitSetJson(c.fruit_set)},
                        {"fruitlets", fruitlets}});
  }
  const AssociationConfig& a = config.association;
  return {{"format", 1},
          {"visits", visits},
          {"config",
           {{"max_center_shift_m", a.max_center_shift_m},
            {"center_sigma_m", a.center_sigma_m},
            {"max_growth_mm_per_day", a.max_growth_mm_per_day},
            {"max_shrink_mm", a.max_shrink_mm},
            {"abscission_ratio", config.fate.abscission_ratio},
            {"fastest_share", config.fate.fastest_share},
            {"size_error_floor_mm", config.size_error_floor_mm}}},
          {"reference_mm_per_day", numberOrNull(season.reference_mm_per_day)},
          {"threshold_mm_per_day", numberOrNull(season.threshold_mm_per_day)},
          {"fruit_set", fruitSetJson(season.fruit_set)},
          {"clusters", clusters}};
}

}  // namespace fvp::host::season
