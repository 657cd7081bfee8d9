#include "fvp/host/perception/capture.h"

#include <yaml-cpp/yaml.h>

#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/input_checks.h"
#include "fvp/host/core/regular_file.h"
#include "fvp/host/core/yaml_config.h"
#include "fvp/host/perception/ply_io.h"

namespace fvp::host {
namespace fs = std::filesystem;
namespace {

constexpr int kFormatVersion = 1;
const char* const kLeft = "left.png";
const char* const kRight = "right.png";
const char* const kCamera = "camera.yaml";
const char* const kDisparity = "disparity.png";
const char* const kMask = "mask.png";
const char* const kRoiPly = "roi.ply";
const char* const kOtherPly = "other.ply";
const char* const kGroundTruth = "ground_truth.json";

[[noreturn]] void fail(const fs::path& file, const std::string& field,
                       const std::string& expected) {
  throw std::runtime_error(file.string() + ": " + field + ": expected " + expected);
}

void writePng(const fs::path& path, const cv::Mat& image) {
  std::vector<uchar> buf;
  if (!cv::imencode(".png", image, buf))
    throw std::runtime_error(path.string() + ": PNG encoding failed");
  writeFileAtomically(path, "image (PNG)",
                      std::string_view(reinterpret_cast<const char*>(buf.data()), buf.size()));
}

cv::Mat encodeDisparity(const cv::Mat& disparity_px, double scale) {
  cv::Mat out(disparity_px.size(), CV_16U);
  for (int v = 0; v < disparity_px.rows; ++v) {
    const float* d = disparity_px.ptr<float>(v);
    auto* o = out.ptr<std::uint16_t>(v);
    for (int u = 0; u < disparity_px.cols; ++u) {
      const double q = std::isfinite(d[u]) && d[u] > 0.0f ? std::round(d[u] * scale) : 0.0;
      o[u] = static_cast<std::uint16_t>(std::min(q, 65535.0));
    }
  }
  return out;
}

std::string cameraYaml(const Capture& c) {
  const StereoIntrinsics& K = c.intrinsics;
  YAML::Emitter e;
  e.SetDoublePrecision(17);
  e << YAML::Comment("fvp capture camera model, see docs/capture-format.md");
  e << YAML::BeginMap;
  e << YAML::Key << "format_version" << YAML::Value << kFormatVersion;
  e << YAML::Key << "width" << YAML::Value << K.width_px;
  e << YAML::Key << "height" << YAML::Value << K.height_px;
  e << YAML::Key << "fx" << YAML::Value << K.fx_px;
  e << YAML::Key << "fy" << YAML::Value << K.fy_px;
  e << YAML::Key << "cx" << YAML::Value << K.cx_px;
  e << YAML::Key << "cy" << YAML::Value << K.cy_px;
  e << YAML::Key << "baseline_m" << YAML::Value << K.baseline_m;
  e << YAML::Key << "disparity_scale" << YAML::Value << c.disparity_scale;
  e << YAML::Key << "T_world_camera" << YAML::Comment("4x4 row-major, left optical frame -> world");
  e << YAML::Value << YAML::BeginSeq;
  const Eigen::Matrix4d T = c.T_world_camera.matrix();
  for (int r = 0; r < 4; ++r) {
    e << YAML::Flow << YAML::BeginSeq;
    for (int col = 0; col < 4; ++col) e << T(r, col);
    e << YAML::EndSeq;
  }
  e << YAML::EndSeq << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

double readNumber(const YAML::Node& root, const fs::path& file, const std::string& key,
                  const std::string& expected) {
  const YAML::Node n = root[key];
  if (!n) fail(file, "field '" + key + "'", expected + " (missing)");
  if (!n.IsScalar()) fail(file, "field '" + key + "'", expected + ", got a non-scalar");
  // Decimal only, as in every config (yaml-cpp alone reads 012 as 10 for an integer).
  if (!isDecimalNumberText(n.Scalar(), false))
    fail(file, "field '" + key + "'", expected + " (a decimal number), got '" + n.Scalar() + "'");
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    fail(file, "field '" + key + "'", expected + ", got '" + n.Scalar() + "'");
  }
}

int readInt(const YAML::Node& root, const fs::path& file, const std::string& key,
            const std::string& expected) {
  const double x = readNumber(root, file, key, expected);
  if (x != std::floor(x) || x < 1 || x > 1e6)
    fail(file, "field '" + key + "'", expected + ", got '" + root[key].Scalar() + "'");
  return static_cast<int>(x);
}

void readCameraYaml(const fs::path& file, Capture& c) {
  std::error_code ec;
  if (!fs::exists(file, ec))
    fail(file, "file", "a readable camera model (required), cannot open it");
  YAML::Node root;
  try {
    // A regular file of bounded size (a FIFO hung the reader, a huge file exhausted memory),
    // one document, no key twice (yaml-cpp keeps both and root[key] took the first).
    root = loadOneYamlDocument(file, file.string(), "camera model", kMaxCameraYamlBytes);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  if (!root.IsMap()) fail(file, "document", "a mapping of camera fields");
  if (root["format_version"]) {
    const double v = readNumber(root, file, "format_version", "format version 1");
    if (v != kFormatVersion) fail(file, "field 'format_version'", "1");
  }
  StereoIntrinsics& K = c.intrinsics;
  K.width_px = readInt(root, file, "width", "a positive integer image width (pixels)");
  K.height_px = readInt(root, file, "height", "a positive integer image height (pixels)");
  if (static_cast<std::int64_t>(K.width_px) * K.height_px > kMaxCapturePixels)
    fail(file, "fields 'width' x 'height'",
         "at most " + std::to_string(kMaxCapturePixels) + " pixels, got " +
             std::to_string(K.width_px) + "x" + std::to_string(K.height_px));
  auto positive = [&](const std::string& key, const std::string& what) {
    const double x = readNumber(root, file, key, what);
    if (!(x > 0.0) || !std::isfinite(x))
      fail(file, "field '" + key + "'", what + ", got '" + root[key].Scalar() + "'");
    return x;
  };
  K.fx_px = positive("fx", "a positive focal length (pixels)");
  K.fy_px = positive("fy", "a positive focal length (pixels)");
  K.cx_px = readNumber(root, file, "cx", "the principal point x (pixels)");
  K.cy_px = readNumber(root, file, "cy", "the principal point y (pixels)");
  if (!std::isfinite(K.cx_px)) fail(file, "field 'cx'", "a finite number");
  if (!std::isfinite(K.cy_px)) fail(file, "field 'cy'", "a finite number");
  K.baseline_m = positive("baseline_m", "a positive stereo baseline (metres)");
  c.disparity_scale = root["disparity_scale"]
                          ? positive("disparity_scale", "a positive disparity scale (e.g. 16)")
                          : kDefaultDisparityScale;

  const std::string tkey = "field 'T_world_camera'";
  const std::string texp = "a 4x4 rigid transform as 4 rows of 4 numbers";
  const YAML::Node T = root["T_world_camera"];
  if (!T) fail(file, tkey, texp + " (missing)");
  if (!T.IsSequence() || T.size() != 4) fail(file, tkey, texp);
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r) {
    if (!T[r].IsSequence() || T[r].size() != 4)
      fail(file, tkey, texp + " (row " + std::to_string(r) + ")");
    for (int col = 0; col < 4; ++col) {
      try {
        if (!T[r][col].IsScalar() || !isDecimalNumberText(T[r][col].Scalar(), false))
          throw YAML::Exception(YAML::Mark::null_mark(), "not a decimal number");
        M(r, col) = T[r][col].as<double>();
      } catch (const YAML::Exception&) {
        fail(file, tkey,
             texp + " (row " + std::to_string(r) + ", column " + std::to_string(col) +
                 " is not a number)");
      }
      if (!std::isfinite(M(r, col))) fail(file, tkey, texp + " (non-finite entry)");
    }
  }
  if ((M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9)
    fail(file, tkey, "last row [0, 0, 0, 1]");
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-5 ||
      R.determinant() < 0.0)
    fail(file, tkey, "a proper rotation (orthonormal, det +1) in the top-left 3x3");
  // Every number plausible before any library sees it (a focal length in metres crashed
  // libapriltag; a 2x2 image crashed its quad search).
  checkIntrinsics(K, file.string());
  if (M.topRightCorner<3, 1>().norm() > kMaxPoseTranslationM)
    fail(file, tkey, "a camera position within 1 km of the world origin");
  // Remove rounding so downstream code can rely on an exact rotation.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  c.T_world_camera.setIdentity();
  c.T_world_camera.linear() = svd.matrixU() * svd.matrixV().transpose();
  c.T_world_camera.translation() = M.topRightCorner<3, 1>();
}

cv::Mat readImage(const fs::path& file, int flags, const StereoIntrinsics& K, bool required) {
  std::error_code ec;
  if (!fs::exists(file, ec)) {
    if (required) fail(file, "file", "an image (required), it is missing");
    return {};
  }
  // A regular file no larger than an image of camera.yaml's size can be (a FIFO would hang
  // the reader, /dev/zero or a sparse 30 GB file would be read until memory ran out), and
  // only its header is read before the header is checked.
  const std::uint64_t max_bytes = maxCaptureImageBytes(K);
  const std::string head = readRegularFileHead(file, "PNG image", max_bytes, 24);
  // Only a PNG of camera.yaml's size reaches the decoder: OpenCV picks its decoder from the
  // content (a PPM or TIFF named left.png would be decoded too) and allocates the image its
  // header claims before it reads a pixel, so 100 bytes could ask for gigabytes. A PNG opens
  // with its 8-byte signature and the IHDR chunk: length, "IHDR", width, height (big-endian).
  static constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (head.size() < 24 || std::memcmp(head.data(), kPngSignature, 8) != 0 ||
      head.compare(12, 4, "IHDR") != 0)
    fail(file, "image", "a PNG file (signature and IHDR header)");
  const auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(head[at + i]);
    return v;
  };
  const std::uint32_t png_width = be32(16), png_height = be32(20);
  const auto sizeError = [&](std::uint64_t w, std::uint64_t h) {
    fail(file, "image size",
         std::to_string(K.width_px) + "x" + std::to_string(K.height_px) +
             " (camera.yaml width x height), got " + std::to_string(w) + "x" + std::to_string(h));
  };
  if (png_width != static_cast<std::uint32_t>(K.width_px) ||
      png_height != static_cast<std::uint32_t>(K.height_px))
    sizeError(png_width, png_height);
  const std::string bytes = readRegularFile(file, "PNG image", max_bytes);
  if (bytes.size() > std::size_t{INT_MAX}) fail(file, "image", "a PNG file below 2 GiB");
  cv::Mat im = cv::imdecode(
      cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data())), flags);
  if (im.empty()) fail(file, "image", "a readable PNG");
  if (im.cols != K.width_px || im.rows != K.height_px) sizeError(im.cols, im.rows);
  return im;
}

void removeIfExists(const fs::path& path) {
  std::error_code ec;
  fs::remove(path, ec);
  if (ec) throw std::runtime_error(path.string() + ": cannot remove a stale file: " + ec.message());
}

}  // namespace

void writeCapture(const fs::path& dir, const Capture& c) {
  const StereoIntrinsics& K = c.intrinsics;
  const cv::Size size(K.width_px, K.height_px);
  auto check = [&](const cv::Mat& m, int type, const char* what, bool optional) {
    if (optional && m.empty()) return;
    if (m.size() != size || m.type() != type)
      throw std::invalid_argument(std::string("writeCapture: ") + what +
                                  ": wrong type or size for the intrinsics' image size");
  };
  check(c.left_bgr, CV_8UC3, "left_bgr", false);
  check(c.right_bgr, CV_8UC3, "right_bgr", false);
  check(c.disparity_px, CV_32F, "disparity_px", true);
  check(c.fruitlet_mask, c.fruitlet_mask.type() == CV_16U ? CV_16U : CV_8U, "fruitlet_mask", true);
  if (!(c.disparity_scale > 0.0))
    throw std::invalid_argument("writeCapture: disparity_scale must be positive");

  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir.string() + ": cannot create directory: " + ec.message());
  // First: an old camera.yaml beside new images would make a mixed capture look complete.
  fs::remove(dir / kCamera, ec);
  if (ec)
    throw std::runtime_error((dir / kCamera).string() +
                             ": cannot remove the old file: " + ec.message());

  writePng(dir / kLeft, c.left_bgr);
  writePng(dir / kRight, c.right_bgr);
  // Optional parts: written when present, removed when absent (no stale files).
  if (!c.disparity_px.empty())
    writePng(dir / kDisparity, encodeDisparity(c.disparity_px, c.disparity_scale));
  else
    removeIfExists(dir / kDisparity);
  if (c.fruitlet_mask.type() == CV_16U) {
    writePng(dir / kMask, c.fruitlet_mask);  // instance ids, as given
  } else if (!c.fruitlet_mask.empty()) {
    cv::Mat mask;
    cv::compare(c.fruitlet_mask, 0, mask, cv::CMP_NE);  // 0 / 255
    writePng(dir / kMask, mask);
  } else {
    removeIfExists(dir / kMask);
  }
  if (c.has_clouds) {
    writePlyPoints(dir / kRoiPly, c.roi_points_m);
    writePlyPoints(dir / kOtherPly, c.other_points_m);
  } else {
    removeIfExists(dir / kRoiPly);
    removeIfExists(dir / kOtherPly);
  }
  if (!c.ground_truth_json.empty())
    writeFileAtomically(dir / kGroundTruth, "ground truth", c.ground_truth_json);
  else
    removeIfExists(dir / kGroundTruth);
  // Last: a directory with camera.yaml holds a complete capture.
  writeFileAtomically(dir / kCamera, "camera", cameraYaml(c));
}

Capture captureOfFrame(const StereoFrame& frame) {
  Capture c;
  c.left_bgr = frame.left_bgr;
  c.right_bgr = frame.right_bgr;
  c.intrinsics = frame.intrinsics;
  c.T_world_camera = frame.T_world_camera;
  c.fruitlet_mask = frame.fruitlet_mask;
  c.disparity_px = frame.disparity_px;
  return c;
}

StereoFrame toStereoFrame(const Capture& c) {
  StereoFrame frame;
  frame.left_bgr = c.left_bgr;
  frame.right_bgr = c.right_bgr;
  frame.intrinsics = c.intrinsics;
  frame.T_world_camera = c.T_world_camera;
  frame.fruitlet_mask = c.fruitlet_mask;
  frame.disparity_px = c.disparity_px;
  return frame;
}

StereoIntrinsics readCaptureIntrinsics(const fs::path& dir) {
  Capture c;
  readCameraYaml(dir / kCamera, c);
  return c.intrinsics;
}

Capture readCapture(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw std::runtime_error(dir.string() + ": not a capture directory");
  Capture c;
  readCameraYaml(dir / kCamera, c);
  const StereoIntrinsics& K = c.intrinsics;
  c.left_bgr = readImage(dir / kLeft, cv::IMREAD_COLOR, K, true);
  c.right_bgr = readImage(dir / kRight, cv::IMREAD_COLOR, K, true);

  cv::Mat disp = readImage(dir / kDisparity, cv::IMREAD_UNCHANGED, K, false);
  if (!disp.empty()) {
    if (disp.type() != CV_16UC1)
      fail(dir / kDisparity, "pixel format", "a single-channel 16-bit PNG (disparity * scale)");
    disp.convertTo(c.disparity_px, CV_32F, 1.0 / c.disparity_scale);
  }
  cv::Mat mask = readImage(dir / kMask, cv::IMREAD_UNCHANGED, K, false);
  if (!mask.empty()) {
    if (mask.type() == CV_16UC1)
      c.fruitlet_mask = mask;  // instance ids
    else if (mask.type() == CV_8UC1)
      cv::compare(mask, 0, c.fruitlet_mask, cv::CMP_NE);
    else
      fail(dir / kMask, "pixel format",
           "a single-channel 8-bit PNG (a mask) or 16-bit PNG (instance ids)");
  }
  const bool roi = fs::exists(dir / kRoiPly), other = fs::exists(dir / kOtherPly);
  if (roi != other)
    throw std::runtime_error((dir / (roi ? kOtherPly : kRoiPly)).string() +
                             ": missing (roi.ply and other.ply come together)");
  if (roi) {
    // Bounded before the PLY reader opens them (a FIFO would hang it).
    for (const char* name : {kRoiPly, kOtherPly})
      checkRegularFile(dir / name, "point cloud (PLY)", maxCaptureCloudBytes(K));
    c.roi_points_m = readPlyPoints(dir / kRoiPly);
    c.other_points_m = readPlyPoints(dir / kOtherPly);
    c.has_clouds = true;
  }
  const fs::path gt = dir / kGroundTruth;
  if (fs::exists(gt)) {
    c.ground_truth_json = readRegularFile(gt, "ground truth (JSON)", kMaxGroundTruthBytes);
    try {
      const auto j = nlohmann::json::parse(c.ground_truth_json);
      if (!j.is_object()) fail(gt, "document", "a JSON object");
    } catch (const nlohmann::json::exception& e) {
      fail(gt, "document", std::string("valid JSON (") + e.what() + ")");
    }
  }
  return c;
}

}  // namespace fvp::host
