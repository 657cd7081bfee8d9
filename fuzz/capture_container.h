// The capture harness's input format: a capture directory's files in a fixed order, separated
// by kPartSeparator (see capture_fuzzer.cpp). make_seeds writes the corpus in this form.
#pragma once

#include <array>
#include <string>
#include <string_view>

namespace fvp::fuzz {

inline constexpr std::array<const char*, 8> kCaptureFiles = {
    "camera.yaml", "left.png", "right.png", "disparity.png",
    "mask.png",    "roi.ply",  "other.ply", "ground_truth.json"};

inline constexpr std::string_view kPartSeparator = "\n--FVP-PART--\n";

/// The parts of an input, one per file of kCaptureFiles (empty: absent).
inline std::array<std::string_view, kCaptureFiles.size()> splitCaptureParts(std::string_view in) {
  std::array<std::string_view, kCaptureFiles.size()> parts{};
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::size_t end = in.find(kPartSeparator);
    parts[i] = in.substr(0, end);
    if (end == std::string_view::npos) break;
    in.remove_prefix(end + kPartSeparator.size());
  }
  return parts;
}

/// The inverse: files' bytes (empty: absent) -> one input.
inline std::string joinCaptureParts(const std::array<std::string, kCaptureFiles.size()>& files) {
  std::string out;
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (i > 0) out += kPartSeparator;
    out += files[i];
  }
  return out;
}

}  // namespace fvp::fuzz
