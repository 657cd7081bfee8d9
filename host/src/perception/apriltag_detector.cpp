#include "fvp/host/perception/apriltag_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

extern "C" {
#include <apriltag/apriltag.h>
#include <apriltag/apriltag_pose.h>
#include <apriltag/common/matd.h>
#include <apriltag/common/zarray.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagCircle49h12.h>
#include <apriltag/tagCustom48h12.h>
#include <apriltag/tagStandard41h12.h>
#include <apriltag/tagStandard52h13.h>
}

#include "task_runner.h"

#include "fvp/host/core/input_checks.h"

namespace fvp::host {

namespace {

struct FamilyFunctions {
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

constexpr FamilyFunctions kFamilies[] = {
    {"tag36h11", tag36h11_create, tag36h11_destroy},
    {"tag25h9", tag25h9_create, tag25h9_destroy},
    {"tag16h5", tag16h5_create, tag16h5_destroy},
    {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
    {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
    {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
    {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy},
};

const FamilyFunctions* findFamily(const std::string& name) {
  for (const FamilyFunctions& f : kFamilies)
    if (name == f.name) return &f;
  return nullptr;
}

std::string familyNames() {
  std::string names;
  for (const FamilyFunctions& f : kFamilies)
    names += (names.empty() ? "" : ", ") + std::string(f.name);
  return names;
}

}  // namespace

void AprilTagDetectorConfig::validate() const {
  auto fail = [](const std::string& field, const std::string& expected) {
    throw std::invalid_argument("AprilTag config: " + field + ": expected " + expected);
  };
  if (!(tag_size_m > 0.0)) fail("tag_size_m", "a positive edge length in metres");
  if (!(quad_decimate >= 1.0f)) fail("quad_decimate", ">= 1");
  if (quad_sigma < 0.0f) fail("quad_sigma", ">= 0");
  if (max_hamming < 0 || max_hamming > 3) fail("max_hamming", "[0, 3]");
  if (tag_id < -1) fail("tag_id", "a tag id of the family or -1 (any)");
  if (!findFamily(family)) fail("family", "one of " + familyNames() + ", got '" + family + "'");
  if (threads < 0) fail("threads", ">= 0 (0: all cores)");
  if (!(search_margin_deg >= 0.0 && search_margin_deg < 45.0))
    fail("search_margin_deg", "[0, 45) degrees");
}

struct AprilTagDetector::Impl {
  apriltag_family_t* family = nullptr;
  void (*destroy_family)(apriltag_family_t*) = nullptr;
  apriltag_detector_t* detector = nullptr;
  ~Impl() {
    if (detector) apriltag_detector_destroy(detector);
    if (family) destroy_family(family);
  }
};

AprilTagDetector::AprilTagDetector(AprilTagDetectorConfig config)
    : config_(config), impl_(std::make_unique<Impl>()) {
  config_.validate();
  const FamilyFunctions& family = *findFamily(config_.family);
  impl_->family = family.create();
  impl_->destroy_family = family.destroy;
  impl_->detector = apriltag_detector_create();
  if (!impl_->family || !impl_->detector)
    throw std::runtime_error("libapriltag: could not create the " + config_.family + " detector");
  // The bit-correction table for max_hamming 2..3 is large but tag36h11 needs it only once.
  apriltag_detector_add_family_bits(impl_->detector, impl_->family, config_.max_hamming);
  impl_->detector->quad_decimate = config_.quad_decimate;
  impl_->detector->quad_sigma = config_.quad_sigma;
  impl_->detector->refine_edges = config_.refine_edges;
  impl_->detector->nthreads = detail::resolveThreads(config_.threads);
}

AprilTagDetector::~AprilTagDetector() = default;

std::vector<TagDetection> AprilTagDetector::detectAll(
    const cv::Mat& image, const StereoIntrinsics& K,
    const Eigen::Isometry3d& T_world_camera) const {
  return detectIn(image, cv::Rect(0, 0, image.cols, image.rows), K, T_world_camera);
}

std::vector<TagDetection> AprilTagDetector::detectIn(
    const cv::Mat& image, cv::Rect window, const StereoIntrinsics& K,
    const Eigen::Isometry3d& T_world_camera) const {
  // libapriltag asserts or crashes on images too small for its decimated quad search and on
  // a degenerate camera model (estimate_tag_pose); neither can hold a tag.
  checkIntrinsics(K, "AprilTagDetector: camera model");
  if (image.cols != K.width_px || image.rows != K.height_px)
    throw std::invalid_argument("AprilTagDetector: the image does not match the camera model");
  cv::Mat gray;
  if (image.type() == CV_8UC3) {
    cv::cvtColor(image(window), gray, cv::COLOR_BGR2GRAY);
  } else if (image.type() == CV_8UC1) {
    gray = image(window);  // libapriltag takes the row stride
  } else {
    throw std::invalid_argument("AprilTagDetector: expected a CV_8UC3 or CV_8UC1 image");
  }
  image_u8_t im{gray.cols, gray.rows, static_cast<int32_t>(gray.step[0]), gray.data};

  std::vector<TagDetection> out;
  std::lock_guard lock(mutex_);
  zarray_t* detections = apriltag_detector_detect(impl_->detector, &im);
  // Freed however this scope is left (a throwing push_back included).
  const std::unique_ptr<zarray_t, void (*)(zarray_t*)> detections_owner(
      detections, apriltag_detections_destroy);
  for (int i = 0; i < zarray_size(detections); ++i) {
    apriltag_detection_t* det = nullptr;
    zarray_get(detections, i, &det);
    if (det->hamming > config_.max_hamming) continue;
    TagDetection d;
    d.tag_id = det->id;
    d.hamming = det->hamming;
    d.decision_margin = det->decision_margin;
    // libapriltag puts pixel centres at +0.5 (AprilRobotics/apriltag#121; measured here as
    // +0.47 px on the simulator's renders, tag_render_test.cpp), OpenCV and StereoIntrinsics
    // at integers: corners are reported in ours, and the pose is estimated with the principal
    // point moved into libapriltag's, which is the same thing for a pinhole camera.
    constexpr double kLibapriltagPixelCentre = 0.5;
    // In a window, pixels are the window's: corners move back by its corner, and the pose
    // is estimated with the principal point moved into the window.
    const Eigen::Vector2d offset(window.x - kLibapriltagPixelCentre,
                                 window.y - kLibapriltagPixelCentre);
    for (int k = 0; k < 4; ++k)
      d.corners_px[k] = Eigen::Vector2d(det->p[k][0], det->p[k][1]) + offset;
    d.center_px = Eigen::Vector2d(det->c[0], det->c[1]) + offset;

    apriltag_detection_info_t info{det,
                                   config_.tag_size_m,
                                   K.fx_px,
                                   K.fy_px,
                                   K.cx_px - window.x + kLibapriltagPixelCentre,
                                   K.cy_px - window.y + kLibapriltagPixelCentre};
    apriltag_pose_t pose{nullptr, nullptr};
    d.object_space_error = estimate_tag_pose(&info, &pose);
    // A degenerate quad can leave no pose (NaN errors pick a missing second solution).
    if (pose.R == nullptr || pose.t == nullptr) {
      std::free(pose.R);
      std::free(pose.t);
      continue;
    }
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R(r, c) = MATD_EL(pose.R, r, c);
    Eigen::Vector3d t(MATD_EL(pose.t, 0, 0), MATD_EL(pose.t, 1, 0), MATD_EL(pose.t, 2, 0));
    // Debian's libapriltag exports only the apriltag_* API, not matd_destroy; a matd_t is one
    // calloc'ed block (header + data), which is all matd_destroy frees.
    std::free(pose.R);
    std::free(pose.t);
    // Re-orthonormalise (orthogonal iteration returns R up to rounding).
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    R = svd.matrixU() * svd.matrixV().transpose();
    if (!R.allFinite() || !t.allFinite()) continue;
    d.T_camera_tag.linear() = R;
    d.T_camera_tag.translation() = t;
    d.T_world_tag = T_world_camera * d.T_camera_tag;
    out.push_back(d);
  }
  return out;
}

std::optional<TagDetection> AprilTagDetector::best(
    const std::vector<TagDetection>& detections) const {
  std::optional<TagDetection> chosen;
  for (const TagDetection& d : detections) {
    if (config_.tag_id >= 0 && d.tag_id != config_.tag_id) continue;
    if (!chosen || d.decision_margin > chosen->decision_margin) chosen = d;
  }
  return chosen;
}

std::optional<TagDetection> AprilTagDetector::detect(
    const cv::Mat& image, const StereoIntrinsics& intrinsics,
    const Eigen::Isometry3d& T_world_camera) const {
  return best(detectAll(image, intrinsics, T_world_camera));
}

cv::Rect AprilTagDetector::searchWindow(const StereoIntrinsics& K,
                                        const Eigen::Isometry3d& T_world_camera,
                                        const Eigen::Isometry3d& T_world_tag_expected) const {
  if (config_.search_margin_deg <= 0.0) return {};
  checkIntrinsics(K, "AprilTagDetector: camera model");
  const Eigen::Isometry3d T_camera_tag = T_world_camera.inverse() * T_world_tag_expected;
  const double h = 0.5 * config_.tag_size_m;
  const double margin_rad = config_.search_margin_deg * M_PI / 180.0;
  // A normalised image coordinate turned by the margin about the camera's axis.
  const auto turned = [&](double t, double sign) {
    return std::tan(std::atan(t) + sign * margin_rad);
  };
  double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(-h, h), Eigen::Vector2d(h, h),
                                   Eigen::Vector2d(h, -h), Eigen::Vector2d(-h, -h)}) {
    const Eigen::Vector3d p = T_camera_tag * Eigen::Vector3d(c.x(), c.y(), 0.0);
    if (!(p.z() > 1e-3)) return {};  // behind or at the camera: no window
    const double x = p.x() / p.z(), y = p.y() / p.z();
    // Near 90 degrees off the axis a turn of the margin leaves the image plane.
    if (std::abs(std::atan(x)) + margin_rad > 1.5 || std::abs(std::atan(y)) + margin_rad > 1.5)
      return {};
    u0 = std::min(u0, K.cx_px + K.fx_px * turned(x, -1.0));
    u1 = std::max(u1, K.cx_px + K.fx_px * turned(x, 1.0));
    v0 = std::min(v0, K.cy_px + K.fy_px * turned(y, -1.0));
    v1 = std::max(v1, K.cy_px + K.fy_px * turned(y, 1.0));
  }
  // From the image's corner: libapriltag fits the quads in float from the window's pixel
  // coordinates, so a window that starts elsewhere moves corners by up to ~5e-5 px (measured),
  // enough to change a trial. Anchored at (0, 0) its detection is the whole image's, bit for
  // bit, and it skips the image's rows below and columns right of the tag.
  const auto clamp = [](double t, int hi) { return int(std::clamp(t, 0.0, double(hi))); };
  const int x0 = 0, y0 = 0;
  const int x1 = clamp(std::ceil(u1) + 1.0, K.width_px);
  const int y1 = clamp(std::ceil(v1) + 1.0, K.height_px);
  // libapriltag needs room for its quad search: a window too small to hold a tag is none.
  constexpr int kLeastSidePx = 32;
  if (x1 < kLeastSidePx || y1 < kLeastSidePx || (u0 > x1 || v0 > y1)) return {};
  return cv::Rect(x0, y0, x1 - x0, y1 - y0);
}

std::optional<TagDetection> AprilTagDetector::detectNear(
    const cv::Mat& image, const StereoIntrinsics& intrinsics,
    const Eigen::Isometry3d& T_world_camera, const Eigen::Isometry3d& T_world_tag_expected) const {
  const cv::Rect window = searchWindow(intrinsics, T_world_camera, T_world_tag_expected);
  // No second search of the whole image: a tag outside the window is more than the margin
  // from where it should be, and where the window misses it the view mostly does not show it
  // (hidden by leaves), which a whole-image search would only confirm at twice the cost.
  if (!window.empty()) return best(detectIn(image, window, intrinsics, T_world_camera));
  return detect(image, intrinsics, T_world_camera);
}

}  // namespace fvp::host
