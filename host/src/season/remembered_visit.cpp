#include "fvp/host/season/remembered_visit.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>

#include "fvp/host/season/season_visit.h"
#include "json_fields.h"

namespace fvp::host::season {
namespace {

using json_fields::fail;
using json_fields::finiteNumber;
using json_fields::poseOf;
using json_fields::vector3;
using nlohmann::json;

/// More views than any visit takes (a cluster's cap is 180 s, a view at least a second).
constexpr std::size_t kMaxViews = 100000;

/// The run's views by their index ("view_log"; none in a fruitlets.json).
std::map<std::size_t, Eigen::Isometry3d> viewPoses(const json& root, const std::string& source) {
  std::map<std::size_t, Eigen::Isometry3d> poses;
  const auto log = root.find("view_log");
  if (log == root.end()) return poses;
  if (!log->is_array() || log->size() > kMaxViews)
    fail(source, "view_log", "an array of at most " + std::to_string(kMaxViews) + " views");
  for (std::size_t i = 0; i < log->size(); ++i) {
    const std::string field = "view_log[" + std::to_string(i) + "]";
    const json& v = (*log)[i];
    if (!v.is_object()) fail(source, field, "an object");
    const auto index = v.find("index");
    if (index == v.end() || !index->is_number_unsigned() || index->get<std::size_t>() >= kMaxViews)
      fail(source, field + ".index", "the view's number (an integer >= 0)");
    poses[index->get<std::size_t>()] = poseOf(v, "position_m", source, field);
  }
  return poses;
}

/// Per sized fruitlet of a cluster, the run's views (first_view + the session's view) that
/// showed it well; every view that sized it when none did (a size from its sphere fit).
std::vector<std::vector<std::size_t>> viewsOfFruitlets(const json& cluster,
                                                       const std::string& source,
                                                       const std::string& field) {
  std::size_t first_view = 0;
  if (const auto f = cluster.find("first_view"); f != cluster.end()) {
    if (!f->is_number_unsigned() || f->get<std::size_t>() >= kMaxViews)
      fail(source, field + "first_view", "the cluster's first view (an integer >= 0)");
    first_view = f->get<std::size_t>();
  }
  std::vector<std::vector<std::size_t>> out;
  const json& fruitlets = cluster.at("sized_fruitlets");  // checked by parseSeasonVisit
  for (std::size_t i = 0; i < fruitlets.size(); ++i) {
    const std::string at = field + "sized_fruitlets[" + std::to_string(i) + "].per_image";
    std::vector<std::size_t> well, any;
    const auto images = fruitlets[i].find("per_image");
    if (images != fruitlets[i].end()) {
      if (!images->is_array()) fail(source, at, "an array");
      for (std::size_t k = 0; k < images->size(); ++k) {
        const json& image = (*images)[k];
        const std::string where = at + "[" + std::to_string(k) + "]";
        const auto view = image.is_object() ? image.find("view") : image.end();
        if (view == image.end() || !view->is_number_unsigned() ||
            view->get<std::size_t>() >= kMaxViews)
          fail(source, where + ".view", "the view's number in the cluster (an integer >= 0)");
        const std::size_t index = first_view + view->get<std::size_t>();
        any.push_back(index);
        const auto well_seen = image.find("well_seen");
        if (well_seen != image.end() && !well_seen->is_boolean())
          fail(source, where + ".well_seen", "true or false");
        if (well_seen != image.end() && well_seen->get<bool>()) well.push_back(index);
      }
    }
    out.push_back(well.empty() ? any : well);
  }
  return out;
}

/// The cluster's memory: its fruitlets (as parseSeasonVisit read them) and its chosen views.
nbv::ClusterMemory memoryOf(const json& cluster, const VisitCluster& read,
                            const std::map<std::size_t, Eigen::Isometry3d>& poses,
                            const RememberedViewRule& rule, const std::string& source,
                            const std::string& field) {
  nbv::ClusterMemory memory;
  for (const SizedFruitlet& f : read.fruitlets)
    memory.fruitlets.push_back({f.at.center_tag_m, f.at.size_mm});
  // Without the tag's pose the views cannot be carried over; the fruitlets still can.
  if (!read.T_world_tag) return memory;
  const Eigen::Isometry3d T_tag_world = read.T_world_tag->inverse();
  // The views the fruitlets name that the log holds, numbered densely for the cover.
  std::vector<std::vector<std::size_t>> seen = viewsOfFruitlets(cluster, source, field);
  std::vector<std::size_t> run_view;
  std::vector<Eigen::Vector3d> positions;
  for (auto& views : seen) {
    std::vector<std::size_t> dense;
    for (const std::size_t v : views) {
      const auto pose = poses.find(v);
      if (pose == poses.end()) continue;  // a fruitlets.json, or a log cut short
      auto at = std::find(run_view.begin(), run_view.end(), v);
      if (at == run_view.end()) {
        run_view.push_back(v);
        positions.push_back((T_tag_world * pose->second).translation());
        at = run_view.end() - 1;
      }
      dense.push_back(std::size_t(at - run_view.begin()));
    }
    views = std::move(dense);
  }
  std::vector<Eigen::Vector3d> centers;
  for (const auto& f : memory.fruitlets) centers.push_back(f.center_tag_m);
  for (const std::size_t k : chooseRememberedViews(positions, centers, seen, rule))
    memory.T_tag_camera.push_back(T_tag_world * poses.at(run_view[k]));
  return memory;
}

}  // namespace

std::vector<std::size_t> chooseRememberedViews(
    const std::vector<Eigen::Vector3d>& camera_positions,
    const std::vector<Eigen::Vector3d>& fruitlet_centers,
    const std::vector<std::vector<std::size_t>>& seen_well, const RememberedViewRule& rule) {
  const std::size_t n = fruitlet_centers.size();
  const double min_cos = std::cos(rule.min_span_deg * M_PI / 180.0);
  std::vector<std::vector<Eigen::Vector3d>> directions(n);  // of the views chosen so far
  const auto direction = [&](std::size_t f, std::size_t v) {
    return (camera_positions.at(v) - fruitlet_centers[f]).normalized();
  };
  const auto spans = [&](std::size_t f) {
    for (std::size_t i = 0; i < directions[f].size(); ++i)
      for (std::size_t j = i + 1; j < directions[f].size(); ++j)
        if (directions[f][i].dot(directions[f][j]) <= min_cos) return true;
    return false;
  };
  // Whether view v moves fruitlet f towards the rule: an image it lacks, or the span.
  const auto helps = [&](std::size_t f, std::size_t v) {
    if (std::find(seen_well[f].begin(), seen_well[f].end(), v) == seen_well[f].end()) return false;
    const bool enough = int(directions[f].size()) >= rule.min_images;
    if (enough && (rule.min_images < 2 || spans(f))) return false;
    if (!enough) return true;
    const Eigen::Vector3d d = direction(f, v);
    return std::any_of(directions[f].begin(), directions[f].end(),
                       [&](const Eigen::Vector3d& e) { return d.dot(e) <= min_cos; });
  };
  std::vector<std::size_t> chosen;
  for (;;) {
    std::size_t best = 0, best_gain = 0;
    for (std::size_t v = 0; v < camera_positions.size(); ++v) {
      if (std::find(chosen.begin(), chosen.end(), v) != chosen.end()) continue;
      std::size_t gain = 0;
      for (std::size_t f = 0; f < n; ++f) gain += helps(f, v) ? 1 : 0;
      if (gain > best_gain) best = v, best_gain = gain;
    }
    if (best_gain == 0) return chosen;
    chosen.push_back(best);
    for (std::size_t f = 0; f < n; ++f)
      if (std::find(seen_well[f].begin(), seen_well[f].end(), best) != seen_well[f].end())
        directions[f].push_back(direction(f, best));
  }
}

std::map<int, nbv::ClusterMemory> parseVisitMemory(const std::string& json_text,
                                                   const std::string& source,
                                                   const RememberedViewRule& rule) {
  if (rule.min_images < 1 || !(rule.min_span_deg >= 0.0 && rule.min_span_deg <= 180.0))
    throw std::invalid_argument(
        "remembered views: expected min_images >= 1 and min_span_deg from 0 to 180");
  // The fruitlets, the tags and the document's shape, checked once, as a season reads them.
  const json root = json_fields::parsed(json_text, source);
  const SeasonVisit visit = json_fields::seasonVisitOf(root, source, 0.0);
  const std::map<std::size_t, Eigen::Isometry3d> poses = viewPoses(root, source);
  std::map<int, nbv::ClusterMemory> out;
  const auto clusters = root.find("clusters");
  const std::size_t count = clusters == root.end() ? 1 : clusters->size();
  for (std::size_t i = 0; i < count; ++i) {
    const json& c = clusters == root.end() ? root : (*clusters)[i];
    const std::string field =
        clusters == root.end() ? std::string() : "clusters[" + std::to_string(i) + "].";
    if (!c.contains("T_world_tag") || !c.contains("sized_fruitlets")) continue;
    const int tag = json_fields::tagIdOf(c, source, field);
    const auto read = std::find_if(visit.clusters.begin(), visit.clusters.end(),
                                   [tag](const VisitCluster& v) { return v.tag_id == tag; });
    if (read == visit.clusters.end() || !read->tag_seen) continue;
    out[tag] = memoryOf(c, *read, poses, rule, source, field);
  }
  return out;
}

std::map<int, nbv::ClusterMemory> readVisitMemory(const std::filesystem::path& path,
                                                  const RememberedViewRule& rule) {
  const std::filesystem::path file = json_fields::visitFile(path);
  return parseVisitMemory(json_fields::fileText(file), file.string(), rule);
}

}  // namespace fvp::host::season
