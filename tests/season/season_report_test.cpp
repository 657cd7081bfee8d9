// The season report (host/report/season_report.h) of two visits of a tree's results
// (tests/season/data): every cluster's fruitlets with their sizes, rates and fates, and a
// figure with a line per fruitlet coloured by its fate.
#include "fvp/host/report/season_report.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "fvp/host/season/season_visit.h"

namespace fvp::host::report {
namespace {

season::SeasonAnalysis treeSeason() {
  const std::filesystem::path data = std::filesystem::path(FVP_SOURCE_DIR) / "tests/season/data";
  return season::analyzeSeason({season::readSeasonVisit(data / "tree_day0.json", 0.0),
                                season::readSeasonVisit(data / "tree_day4.json", 4.0)});
}

TEST(SeasonReport, EveryClusterAndFruitletWithItsFate) {
  const season::SeasonAnalysis s = treeSeason();
  const std::string md = seasonMarkdown(s, "season.png");
  EXPECT_NE(md.find("![size against day, by predicted fate](season.png)"), std::string::npos);
  std::size_t rows = 0;
  for (const season::ClusterSeason& c : s.clusters) {
    EXPECT_NE(md.find("## Tag " + std::to_string(c.tag_id)), std::string::npos);
    rows += c.tracks.size();
  }
  std::size_t fates = 0;
  for (const char* word :
       {"| persists |", "| abscises |", "| gone |", "| unknown |", "| unconfirmed |"})
    for (std::size_t at = md.find(word); at != std::string::npos; at = md.find(word, at + 1))
      ++fates;
  EXPECT_EQ(fates, rows);
  EXPECT_EQ(seasonMarkdown(s, "").find("!["), std::string::npos);

  const std::string gp = seasonFigureScript(s);
  EXPECT_NE(gp.find("set multiplot layout"), std::string::npos);
  std::size_t lines = 0;
  for (std::size_t at = gp.find("with linespoints"); at != std::string::npos;
       at = gp.find("with linespoints", at + 1))
    ++lines;
  EXPECT_EQ(lines, rows);
}

TEST(SeasonReport, WritesTheTextAndTheFigure) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("fvp_season_report_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::vector<std::string> warnings;
  const bool drawn =
      writeSeasonReport(treeSeason(), dir, [&](const std::string& w) { warnings.push_back(w); });
  EXPECT_TRUE(drawn) << (warnings.empty() ? "" : warnings.front());
  std::ifstream png(dir / "season.png", std::ios::binary);
  char magic[4] = {};
  png.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  EXPECT_TRUE(std::filesystem::exists(dir / "season.md"));
  EXPECT_TRUE(std::filesystem::exists(dir / "season_viewer.html"));
  std::ifstream md(dir / "season.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("](season_viewer.html)"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(SeasonReport, TheViewerShowsEveryFruitletWhereItsTagPutsItColouredByItsFate) {
  const season::SeasonAnalysis s = treeSeason();
  const nlohmann::json scene = seasonViewerScene(s);
  std::size_t tracks = 0;
  for (const season::ClusterSeason& c : s.clusters) tracks += c.tracks.size();
  ASSERT_EQ(scene["detections"].size(), tracks);
  ASSERT_EQ(scene["tags"].size(), s.clusters.size());
  std::size_t d = 0;
  for (const season::ClusterSeason& c : s.clusters) {
    ASSERT_TRUE(c.T_world_tag.has_value()) << "the day-4 result gives every tag's pose";
    for (const std::size_t t : c.tracks) {
      const season::FruitletTrack& track = s.tracks[t];
      const nlohmann::json& f = scene["detections"][d++];
      const Eigen::Vector3d expected = *c.T_world_tag * track.sizes.back().sized.at.center_tag_m;
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(f["center_m"][i].get<double>(), expected[i], 1e-9);
      const std::string fate = f["fate"];
      EXPECT_EQ(fate, track.unconfirmed ? "unconfirmed"
                      : track.gone      ? "gone"
                                        : season::toString(track.fate.fate));
    }
  }
}

}  // namespace
}  // namespace fvp::host::report
