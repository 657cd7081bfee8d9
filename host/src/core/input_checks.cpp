#include "fvp/host/core/input_checks.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace fvp::host {
namespace {

std::string text(double v) {
  std::ostringstream out;
  out.precision(9);
  out << v;
  return out.str();
}

/// The focal length (pixels) that gives fov_deg across side_px pixels.
double focalForFov(double side_px, double fov_deg) {
  return 0.5 * side_px / std::tan(0.5 * fov_deg * M_PI / 180.0);
}

}  // namespace

void failField(const std::string& source, const std::string& field, const std::string& expected,
               const std::string& got) {
  throw std::invalid_argument(source + ": field '" + field + "': expected " + expected + ", got " +
                              got);
}

void checkNumber(double value, double lo, double hi, const std::string& source,
                 const std::string& field, const std::string& unit) {
  // `!(lo <= v)` also rejects NaN.
  if (!std::isfinite(value) || !(lo <= value) || !(value <= hi))
    failField(source, field, "a number in [" + text(lo) + ", " + text(hi) + "] " + unit,
              text(value));
}

void checkIntrinsics(const StereoIntrinsics& K, const std::string& source) {
  const auto side = [&](int v, const char* field) {
    if (v < kMinImageSidePx || v > kMaxImageSidePx)
      failField(source, field,
                "an image side of " + std::to_string(kMinImageSidePx) + " to " +
                    std::to_string(kMaxImageSidePx) + " pixels",
                std::to_string(v));
  };
  side(K.width_px, "width");
  side(K.height_px, "height");
  const auto focal = [&](double f, int side_px, const char* field) {
    const double lo = focalForFov(side_px, kMaxFieldOfViewDeg);
    const double hi = focalForFov(side_px, kMinFieldOfViewDeg);
    if (!std::isfinite(f) || !(lo <= f) || !(f <= hi))
      failField(source, field,
                "a focal length in pixels giving a field of view of " + text(kMinFieldOfViewDeg) +
                    " to " + text(kMaxFieldOfViewDeg) + " degrees over " + std::to_string(side_px) +
                    " px (" + text(lo) + " to " + text(hi) + " px)",
                text(f));
  };
  focal(K.fx_px, K.width_px, "fx");
  focal(K.fy_px, K.height_px, "fy");
  checkNumber(K.cx_px, 0.0, K.width_px, source, "cx", "pixels (inside the image)");
  checkNumber(K.cy_px, 0.0, K.height_px, source, "cy", "pixels (inside the image)");
  checkNumber(K.baseline_m, kMinBaselineM, kMaxBaselineM, source, "baseline_m", "metres");
}

void checkPose(const Eigen::Isometry3d& T, const std::string& source, const std::string& field) {
  if (!T.matrix().allFinite()) failField(source, field, "a pose with finite entries", "NaN or inf");
  const Eigen::Matrix3d R = T.linear();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
      R.determinant() < 0.0)
    failField(source, field, "a rotation (orthonormal, det +1)", "another matrix");
  if (!(T.translation().norm() <= kMaxPoseTranslationM))
    failField(source, field,
              "a position within " + text(kMaxPoseTranslationM) + " m of the world origin",
              text(T.translation().norm()) + " m away");
}

}  // namespace fvp::host
