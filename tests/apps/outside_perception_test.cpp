// A capture's own mask.png and disparity.png are used as given (a robot's segmentation and
// stereo): a set whose images are desaturated, so HSV segmentation finds nothing, but which
// carries the mask is sized exactly as the colour set; without the mask it sizes nothing and
// says why. A set sized without its tag, from a region given in the perception config.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "fvp/host/core/subprocess.h"

namespace fs = std::filesystem;

namespace {

nlohmann::json sizeSet(const fs::path& set, const fs::path& out, std::string* stderr_text,
                       const fs::path& config = {}) {
  std::vector<std::string> argv = {FVP_BINARY,  "size", "--captures", set.string(),
                                   "--backend", "cpu",  "--out",      out.string()};
  if (!config.empty()) argv.insert(argv.end(), {"--config", config.string()});
  const auto run = fvp::host::runProgram(argv, "");
  if (stderr_text) *stderr_text = run.stderr_text;
  EXPECT_EQ(run.exit_code, 0) << run.stderr_text;
  std::ifstream in(out / "fruitlets.json");
  return nlohmann::json::parse(in);
}

void desaturate(const fs::path& png) {
  cv::Mat grey;
  cv::cvtColor(cv::imread(png.string(), cv::IMREAD_COLOR), grey, cv::COLOR_BGR2GRAY);
  cv::Mat bgr;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  ASSERT_TRUE(cv::imwrite(png.string(), bgr));
}

TEST(OutsidePerception, AGreySetWithItsMaskIsSizedAsTheColourSet) {
  const fs::path dir = fs::path(::testing::TempDir()) / "fvp_outside_perception";
  fs::remove_all(dir);
  const auto capture =
      fvp::host::runProgram({FVP_BINARY, "capture", "--seed", "1", "--views", "3", "--arc-deg",
                             "60", "--out", (dir / "colour").string()},
                            "");
  ASSERT_EQ(capture.exit_code, 0) << capture.stderr_text;
  fs::copy(dir / "colour", dir / "grey", fs::copy_options::recursive);
  for (const auto& view : fs::directory_iterator(dir / "grey")) {
    desaturate(view.path() / "left.png");
    desaturate(view.path() / "right.png");
  }
  fs::copy(dir / "grey", dir / "grey_no_mask", fs::copy_options::recursive);
  for (const auto& view : fs::directory_iterator(dir / "grey_no_mask"))
    fs::remove(view.path() / "mask.png");

  const nlohmann::json colour = sizeSet(dir / "colour", dir / "out_colour", nullptr);
  const nlohmann::json grey = sizeSet(dir / "grey", dir / "out_grey", nullptr);
  ASSERT_GT(colour["sized_fruitlets"].size(), 0u);
  ASSERT_EQ(grey["sized_fruitlets"].size(), colour["sized_fruitlets"].size());
  for (std::size_t i = 0; i < colour["sized_fruitlets"].size(); ++i)
    EXPECT_DOUBLE_EQ(grey["sized_fruitlets"][i]["size_mm"].get<double>(),
                     colour["sized_fruitlets"][i]["size_mm"].get<double>());
  EXPECT_EQ(grey["metrics"]["match_percent"], colour["metrics"]["match_percent"]);

  // No tag the detector accepts (a tag id the set does not show), but the region given in
  // the world frame (the fruitlets' mean centre from the set's ground truth): sized alike.
  std::ifstream gt_in(dir / "colour" / "000" / "ground_truth.json");
  const nlohmann::json gt = nlohmann::json::parse(gt_in);
  double c[3] = {0, 0, 0};
  for (const auto& f : gt["fruitlets"])
    for (int a = 0; a < 3; ++a) c[a] += f["center_m"][a].get<double>() / gt["fruitlets"].size();
  {
    std::ofstream(dir / "region.yaml")
        << "tag_id: 586\nregion_center_m: [" << c[0] << ", " << c[1] << ", " << c[2] << "]\n";
    std::ofstream(dir / "no_region.yaml") << "tag_id: 586\n";
  }
  std::string tagless;
  const nlohmann::json no_region =
      sizeSet(dir / "colour", dir / "out_no_region", &tagless, dir / "no_region.yaml");
  EXPECT_EQ(no_region["sized_fruitlets"].size(), 0u);
  EXPECT_NE(tagless.find("no capture showed the AprilTag (tag36h11 id 586)"), std::string::npos)
      << tagless;
  const nlohmann::json region =
      sizeSet(dir / "colour", dir / "out_region", nullptr, dir / "region.yaml");
  EXPECT_TRUE(region["cluster_region_found"].get<bool>());
  EXPECT_GE(region["metrics"]["match_percent"].get<double>(),
            colour["metrics"]["match_percent"].get<double>() - 1e-9);

  std::string warnings;
  const nlohmann::json no_mask = sizeSet(dir / "grey_no_mask", dir / "out_no_mask", &warnings);
  EXPECT_EQ(no_mask["sized_fruitlets"].size(), 0u);
  EXPECT_NE(warnings.find("no fruitlet pixels segmented"), std::string::npos) << warnings;
}

}  // namespace
