// An earlier visit read as a later one's memory (host/season/remembered_visit.h): the views
// chosen give every fruitlet the stop's evidence where the visit's views can (checked against
// every subset of a small visit), poses land in the tag's frame, and bad files are errors
// naming the field.
#include "fvp/host/season/remembered_visit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>

namespace fvp::host::season {
namespace {

/// Whether the views give fruitlet f the rule's images from directions apart.
bool satisfied(const std::vector<std::size_t>& views, std::size_t f,
               const std::vector<Eigen::Vector3d>& cameras,
               const std::vector<Eigen::Vector3d>& centers,
               const std::vector<std::vector<std::size_t>>& seen, const RememberedViewRule& rule) {
  std::vector<Eigen::Vector3d> d;
  for (const std::size_t v : views)
    if (std::find(seen[f].begin(), seen[f].end(), v) != seen[f].end())
      d.push_back((cameras[v] - centers[f]).normalized());
  if (int(d.size()) < rule.min_images) return false;
  if (rule.min_images < 2) return true;
  for (std::size_t i = 0; i < d.size(); ++i)
    for (std::size_t j = i + 1; j < d.size(); ++j)
      if (d[i].dot(d[j]) <= std::cos(rule.min_span_deg * M_PI / 180.0)) return true;
  return false;
}

TEST(RememberedVisit, ChosenViewsGiveEveryFruitletWhatAllTheViewsCould) {
  const RememberedViewRule rule;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const std::size_t views = 3 + seed % 6, fruitlets = 1 + seed % 5;
    std::vector<Eigen::Vector3d> cameras, centers;
    for (std::size_t v = 0; v < views; ++v)
      cameras.push_back(Eigen::Vector3d(0.3 * u(rng), 0.3 * u(rng), -0.3));
    for (std::size_t f = 0; f < fruitlets; ++f)
      centers.push_back(Eigen::Vector3d(0.02 * u(rng), 0.02 * u(rng), 0.0));
    std::vector<std::vector<std::size_t>> seen(fruitlets);
    for (std::size_t f = 0; f < fruitlets; ++f)
      for (std::size_t v = 0; v < views; ++v)
        if (u(rng) > -0.2) seen[f].push_back(v);
    const std::vector<std::size_t> chosen = chooseRememberedViews(cameras, centers, seen, rule);
    std::vector<std::size_t> all(views);
    for (std::size_t v = 0; v < views; ++v) all[v] = v;
    std::size_t fewest = views;  // brute force: the smallest subset that does as well as all
    for (std::size_t mask = 0; mask < (std::size_t{1} << views); ++mask) {
      std::vector<std::size_t> subset;
      for (std::size_t v = 0; v < views; ++v)
        if (mask >> v & 1) subset.push_back(v);
      bool as_well = true;
      for (std::size_t f = 0; f < fruitlets; ++f)
        as_well = as_well && (satisfied(subset, f, cameras, centers, seen, rule) ||
                              !satisfied(all, f, cameras, centers, seen, rule));
      if (as_well) fewest = std::min(fewest, subset.size());
    }
    for (std::size_t f = 0; f < fruitlets; ++f) {
      if (satisfied(all, f, cameras, centers, seen, rule)) {
        EXPECT_TRUE(satisfied(chosen, f, cameras, centers, seen, rule))
            << "seed " << seed << ", fruitlet " << f;
      }
    }
    // A greedy cover, not the least one: within the greedy bound, and never every view for
    // nothing.
    EXPECT_LE(chosen.size(), 2 * fewest + 1) << "seed " << seed;
  }
}

nlohmann::json pose(const Eigen::Vector3d& t, const char* key) {
  return {{key, {t.x(), t.y(), t.z()}}, {"quaternion_wxyz", {1.0, 0.0, 0.0, 0.0}}};
}

/// A tree's result of one cluster (tag 7, at x = 1) seen from views 3..5 of the run.
nlohmann::json treeResult() {
  nlohmann::json view_log = nlohmann::json::array();
  for (int v = 0; v < 6; ++v) {
    nlohmann::json entry = pose(Eigen::Vector3d(1.0 + 0.1 * v, 0.0, -0.3), "position_m");
    entry["index"] = v;
    view_log.push_back(entry);
  }
  const auto image = [](int view, bool well) {
    return nlohmann::json{{"view", view}, {"well_seen", well}};
  };
  nlohmann::json cluster = {{"tag_id", 7},
                            {"first_view", 3},
                            {"T_world_tag", pose(Eigen::Vector3d(1.0, 0.0, 0.0), "translation_m")},
                            {"sized_fruitlets",
                             {{{"center_tag_m", {0.0, 0.0, 0.0}},
                               {"size_mm", 8.0},
                               {"per_image", {image(0, true), image(2, true), image(1, false)}}},
                              {{"center_tag_m", {0.01, 0.0, 0.0}},
                               {"size_mm", 6.0},
                               {"per_image", {image(0, true), image(2, true)}}}}}};
  return {{"view_log", view_log}, {"clusters", {cluster, {{"tag_id", 8}, {"status", "no_tag"}}}}};
}

TEST(RememberedVisit, ReadsEachClustersFruitletsAndViewsInItsTagsFrame) {
  const auto memory = parseVisitMemory(treeResult().dump(), "r.json");
  ASSERT_EQ(memory.size(), 1u) << "the cluster whose tag was never seen is not remembered";
  const nbv::ClusterMemory& m = memory.at(7);
  ASSERT_EQ(m.fruitlets.size(), 2u);
  EXPECT_DOUBLE_EQ(m.fruitlets[1].size_mm, 6.0);
  EXPECT_DOUBLE_EQ(m.fruitlets[1].center_tag_m.x(), 0.01);
  // Views 3 and 5 of the run (the cluster's 0 and 2) show both: x 0.3 and 0.5 from the tag.
  ASSERT_EQ(m.T_tag_camera.size(), 2u);
  std::vector<double> x = {m.T_tag_camera[0].translation().x(),
                           m.T_tag_camera[1].translation().x()};
  std::sort(x.begin(), x.end());
  EXPECT_NEAR(x[0], 0.3, 1e-12);
  EXPECT_NEAR(x[1], 0.5, 1e-12);
  EXPECT_NEAR(m.T_tag_camera[0].translation().z(), -0.3, 1e-12);
}

TEST(RememberedVisit, AFruitletsFileGivesFruitletsWithoutViews) {
  nlohmann::json sizing = treeResult()["clusters"][0];
  sizing.erase("first_view");
  const auto memory = parseVisitMemory(sizing.dump(), "fruitlets.json");
  ASSERT_EQ(memory.size(), 1u);
  EXPECT_EQ(memory.begin()->second.fruitlets.size(), 2u);
  EXPECT_TRUE(memory.begin()->second.T_tag_camera.empty());
}

TEST(RememberedVisit, BadFieldsAreErrorsNamingThem) {
  const auto fails = [](nlohmann::json r, const std::string& field) {
    try {
      parseVisitMemory(r.dump(), "r.json");
      ADD_FAILURE() << "accepted a bad " << field;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("r.json: " + field), std::string::npos) << e.what();
    }
  };
  nlohmann::json r = treeResult();
  r["view_log"][2].erase("index");
  fails(r, "view_log[2].index");
  r = treeResult();
  r["view_log"][1]["quaternion_wxyz"] = {2.0, 0.0, 0.0, 0.0};
  fails(r, "view_log[1].quaternion_wxyz");
  r = treeResult();
  r["clusters"][0]["first_view"] = -1;
  fails(r, "clusters[0].first_view");
  r = treeResult();
  r["clusters"][0]["sized_fruitlets"][1]["per_image"][0]["view"] = "two";
  fails(r, "clusters[0].sized_fruitlets[1].per_image[0].view");
  r = treeResult();
  r["clusters"][0]["T_world_tag"]["translation_m"] = "here";
  fails(r, "clusters[0].T_world_tag.translation_m");
  EXPECT_THROW(parseVisitMemory("{", "r.json"), std::runtime_error);
  EXPECT_THROW(readVisitMemory("/nonexistent/visit"), std::runtime_error);
}

}  // namespace
}  // namespace fvp::host::season
