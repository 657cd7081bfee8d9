// readCapture (host/src/perception/capture.cpp) on a capture directory made from the input.
// The input is the capture's files in a fixed order, separated by kPartSeparator:
//   camera.yaml, left.png, right.png, disparity.png, mask.png, roi.ply, other.ply,
//   ground_truth.json
// An empty (or missing) part leaves its file out of the directory; parts past the eighth
// are ignored. fuzz/corpus/capture holds small real captures in this form (make_seeds).
#include <yaml-cpp/yaml.h>

#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string_view>

#include "capture_container.h"
#include "fuzz_support.h"
#include "fvp/host/perception/capture.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fz = fvp::fuzz;
  const std::filesystem::path dir = fz::scratchDir() / "capture";
  std::filesystem::create_directories(dir);
  const std::array<std::string_view, fz::kCaptureFiles.size()> parts =
      fz::splitCaptureParts(std::string_view(reinterpret_cast<const char*>(data), size));
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (parts[i].empty())
      fz::removeFile(dir / fz::kCaptureFiles[i]);
    else
      fz::writeFile(dir / fz::kCaptureFiles[i], parts[i]);
  }
  try {
    const fvp::host::Capture c = fvp::host::readCapture(dir);
    // What readCapture promises about a capture it accepts.
    const auto& K = c.intrinsics;
    const bool ok =
        K.width_px > 0 && K.height_px > 0 && K.fx_px > 0 && K.fy_px > 0 && std::isfinite(K.fx_px) &&
        std::isfinite(K.fy_px) && std::isfinite(K.cx_px) && std::isfinite(K.cy_px) &&
        K.baseline_m > 0 && std::isfinite(K.baseline_m) && c.disparity_scale > 0 &&
        std::isfinite(c.disparity_scale) && c.left_bgr.cols == K.width_px &&
        c.left_bgr.rows == K.height_px && c.left_bgr.type() == CV_8UC3 &&
        c.right_bgr.size() == c.left_bgr.size() && c.right_bgr.type() == CV_8UC3 &&
        (c.disparity_px.empty() ||
         (c.disparity_px.size() == c.left_bgr.size() && c.disparity_px.type() == CV_32F)) &&
        (c.fruitlet_mask.empty() ||
         (c.fruitlet_mask.size() == c.left_bgr.size() &&
          (c.fruitlet_mask.type() == CV_8U || c.fruitlet_mask.type() == CV_16U))) &&
        c.T_world_camera.matrix().allFinite();
    if (!ok) {
      std::fprintf(stderr, "fvp fuzz: readCapture accepted an inconsistent capture\n");
      std::abort();
    }
  } catch (const YAML::Exception& e) {
    fz::reportEscapedException("yaml-cpp", e);
  } catch (const nlohmann::json::exception& e) {
    fz::reportEscapedException("nlohmann_json", e);
  } catch (const std::exception&) {
    // Rejected: expected for most inputs.
  }
  return 0;
}
