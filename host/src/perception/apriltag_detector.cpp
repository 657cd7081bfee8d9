#include "fvp/host/perception/apriltag_detector.h"

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
  // libapriltag asserts or crashes on images too small for its decimated quad search and on
  // a degenerate camera model (estimate_tag_pose); neither can hold a tag.
  checkIntrinsics(K, "AprilTagDetector: camera model");
  if (image.cols != K.width_px || image.rows != K.height_px)
    throw std::invalid_argument("AprilTagDetector: the image does not match the camera model");
  cv::Mat gray;
  if (image.type() == CV_8UC3) {
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  } else if (image.type() == CV_8UC1) {
    gray = image.isContinuous() ? image : image.clone();
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
    for (int k = 0; k < 4; ++k)
      d.corners_px[k] = {det->p[k][0] - kLibapriltagPixelCentre,
                         det->p[k][1] - kLibapriltagPixelCentre};
    d.center_px = {det->c[0] - kLibapriltagPixelCentre, det->c[1] - kLibapriltagPixelCentre};

    apriltag_detection_info_t info{det,
                                   config_.tag_size_m,
                                   K.fx_px,
                                   K.fy_px,
                                   K.cx_px + kLibapriltagPixelCentre,
                                   K.cy_px + kLibapriltagPixelCentre};
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

std::optional<TagDetection> AprilTagDetector::detect(
    const cv::Mat& image, const StereoIntrinsics& intrinsics,
    const Eigen::Isometry3d& T_world_camera) const {
  std::optional<TagDetection> best;
  for (const TagDetection& d : detectAll(image, intrinsics, T_world_camera)) {
    if (config_.tag_id >= 0 && d.tag_id != config_.tag_id) continue;
    if (!best || d.decision_margin > best->decision_margin) best = d;
  }
  return best;
}

}  // namespace fvp::host
