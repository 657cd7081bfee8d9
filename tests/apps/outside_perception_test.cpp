// A capture's own mask.png and disparity.png are used as given (a robot's segmentation and
// stereo): a set whose images are desaturated, so HSV segmentation finds nothing, but which
// carries the mask is sized exactly as the colour set; without the mask it sizes nothing and
// says why.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "fvp/host/core/subprocess.h"

namespace fs = std::filesystem;

namespace {

nlohmann::json sizeSet(const fs::path& set, const fs::path& out, std::string* stderr_text) {
  const auto run = fvp::host::runProgram(
      {FVP_BINARY, "size", "--captures", set.string(), "--backend", "cpu", "--out", out.string()},
      "");
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

  std::string warnings;
  const nlohmann::json no_mask = sizeSet(dir / "grey_no_mask", dir / "out_no_mask", &warnings);
  EXPECT_EQ(no_mask["sized_fruitlets"].size(), 0u);
  EXPECT_NE(warnings.find("no fruitlet pixels segmented"), std::string::npos) << warnings;
}

}  // namespace
