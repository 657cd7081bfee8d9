#include "fvp/host/season/season_visit.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>

#include "fvp/host/nbv/stop_rule.h"
#include "fvp/host/season/growth_rate.h"
#include "json_fields.h"

namespace fvp::host::season {
namespace {

using json_fields::fail;
using json_fields::finiteNumber;
using json_fields::tagIdOf;
using json_fields::vector3;
using nlohmann::json;

/// More than a cluster holds by far (3-8 fruitlets): a file with more is not a cluster's
/// sizing, and the association's exact search grows with it.
constexpr std::size_t kMaxFruitletsPerCluster = 64;

SizedFruitlet sizedFruitlet(const json& f, const std::string& source, const std::string& field) {
  if (!f.is_object()) fail(source, field, "an object");
  SizedFruitlet out;
  const auto center = f.find("center_tag_m");
  if (center == f.end()) fail(source, field + ".center_tag_m", "the centre in the tag's frame");
  out.at.center_tag_m = vector3(*center, source, field + ".center_tag_m");
  const auto size = f.find("size_mm");
  if (size == f.end()) fail(source, field + ".size_mm", "a size in mm");
  out.at.size_mm = finiteNumber(*size, source, field + ".size_mm");
  if (!(out.at.size_mm > 0.0)) fail(source, field + ".size_mm", "a size > 0");
  const auto support = f.find("support");
  if (support == f.end()) return out;
  if (!support->is_object()) fail(source, field + ".support", "an object");
  if (const auto images = support->find("well_seen_images"); images != support->end()) {
    if (!images->is_number_integer() || images->get<std::int64_t>() < 0 ||
        images->get<std::int64_t>() > std::numeric_limits<int>::max())
      fail(source, field + ".support.well_seen_images",
           "a count of images (an integer from 0 to " +
               std::to_string(std::numeric_limits<int>::max()) + ")");
    out.well_seen_images = images->get<int>();
  }
  const auto se = support->find("size_stderr_mm");
  if (se == support->end() || se->is_null()) return out;
  const double v = finiteNumber(*se, source, field + ".support.size_stderr_mm");
  // -1: fewer than two well-seen images (the sizer's "unknown"); 0: no spread measured.
  if (v != -1.0 && v != 0.0 && !(v >= kMinStandardErrorMm && v <= kMaxStandardErrorMm))
    fail(source, field + ".support.size_stderr_mm",
         "-1 or 0 (unknown) or a standard error from 1e-6 to 1000 mm");
  if (v > 0.0) out.standard_error_mm = v;
  return out;
}

/// Whether the cluster's "stop_reason" (absent: yes) says the visit looked until its own stop
/// held; `stop_rule` is the run's "stop"."rule" (the budget rule: the paper's protocol, every
/// cluster given its whole budget).
bool searchedOf(const json& sizing, std::optional<nbv::StopRule> stop_rule,
                const std::string& source, const std::string& field) {
  const auto reason = sizing.find("stop_reason");
  if (reason == sizing.end() || reason->is_null()) return true;
  if (!reason->is_string()) fail(source, field + "stop_reason", "a string (the cluster's stop)");
  const std::string& why = reason->get_ref<const std::string&>();
  // The budget's stop condition (nbv::budget) is named as the budget rule.
  return why == "cluster_done" ||
         (stop_rule == nbv::StopRule::kBudget && why == nbv::toString(nbv::StopRule::kBudget));
}

/// The run's stop rule ("stop": {"rule": ...}), none when the file does not say.
std::optional<nbv::StopRule> stopRuleOf(const json& root, const std::string& source) {
  const auto stop = root.find("stop");
  if (stop == root.end() || stop->is_null()) return std::nullopt;
  if (!stop->is_object()) fail(source, "stop", "an object (the run's stop rule)");
  const auto rule = stop->find("rule");
  if (rule == stop->end() || rule->is_null()) return std::nullopt;
  const std::optional<nbv::StopRule> parsed =
      rule->is_string() ? nbv::stopRuleFromString(rule->get_ref<const std::string&>())
                        : std::nullopt;
  if (!parsed) fail(source, "stop.rule", "one of " + nbv::stopRuleNames());
  return parsed;
}

/// A cluster's sizing: "sized_fruitlets" with the tag frame ("T_world_tag" present), or no
/// tag seen (no "T_world_tag": nothing to place).
VisitCluster clusterOf(const json& sizing, int tag_id, std::optional<nbv::StopRule> stop_rule,
                       const std::string& source, const std::string& field) {
  VisitCluster cluster;
  cluster.tag_id = tag_id;
  cluster.searched = searchedOf(sizing, stop_rule, source, field);
  cluster.tag_seen = sizing.contains("T_world_tag");
  if (!cluster.tag_seen) return cluster;
  if (const json& pose = sizing["T_world_tag"]; pose.is_object() && pose.contains("translation_m"))
    cluster.T_world_tag = json_fields::poseOf(pose, "translation_m", source, field + "T_world_tag");
  const auto fruitlets = sizing.find("sized_fruitlets");
  if (fruitlets == sizing.end() || !fruitlets->is_array())
    fail(source, field + "sized_fruitlets", "an array of sized fruitlets");
  if (fruitlets->size() > kMaxFruitletsPerCluster)
    fail(source, field + "sized_fruitlets",
         "at most " + std::to_string(kMaxFruitletsPerCluster) + " fruitlets in a cluster");
  for (std::size_t i = 0; i < fruitlets->size(); ++i)
    cluster.fruitlets.push_back(sizedFruitlet(
        (*fruitlets)[i], source, field + "sized_fruitlets[" + std::to_string(i) + "]"));
  return cluster;
}

}  // namespace

SeasonVisit parseSeasonVisit(const std::string& json_text, const std::string& source, double day) {
  if (!std::isfinite(day)) fail(source, "day", "a finite number of days");
  return json_fields::seasonVisitOf(json_fields::parsed(json_text, source), source, day);
}

SeasonVisit json_fields::seasonVisitOf(const json& root, const std::string& source, double day) {
  if (!std::isfinite(day)) fail(source, "day", "a finite number of days");
  if (!root.is_object())
    fail(source, "the document", "an object (a result.json or fruitlets.json)");
  SeasonVisit visit;
  visit.day = day;
  visit.source = source;
  const std::optional<nbv::StopRule> stop_rule = stopRuleOf(root, source);
  const auto clusters = root.find("clusters");
  if (clusters == root.end()) {
    visit.clusters.push_back(clusterOf(root, tagIdOf(root, source, ""), stop_rule, source, ""));
    return visit;
  }
  if (!clusters->is_array()) fail(source, "clusters", "an array (a tree's clusters)");
  std::map<int, std::size_t> index_of_tag;
  for (std::size_t i = 0; i < clusters->size(); ++i) {
    const std::string field = "clusters[" + std::to_string(i) + "].";
    const json& c = (*clusters)[i];
    if (!c.is_object()) fail(source, field, "an object");
    if (!c.contains("sized_fruitlets") && !c.contains("T_world_tag")) continue;  // not run
    const int tag = tagIdOf(c, source, field);
    if (const auto [it, added] = index_of_tag.emplace(tag, i); !added)
      fail(source, field + "tag_id",
           "a tag of its own (clusters[" + std::to_string(it->second) + "] has tag " +
               std::to_string(tag) + " too)");
    visit.clusters.push_back(clusterOf(c, tag, stop_rule, source, field));
  }
  return visit;
}

SeasonVisit readSeasonVisit(const std::filesystem::path& path, double day) {
  const std::filesystem::path file = json_fields::visitFile(path);
  return parseSeasonVisit(json_fields::fileText(file), file.string(), day);
}

}  // namespace fvp::host::season
