// The one validation layer for numbers that come from files and the command line (camera
// models, poses, sizes): each is checked finite and physically plausible before any library
// (AprilTag, OpenCV, Embree) sees it, because those libraries assert or crash on input they
// do not expect. Errors name the source (a file, an option), the field and what was expected.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::host {

/// Smallest image side the perception chain accepts: an AprilTag needs about 10 px to
/// decode (8 data cells + border) and libapriltag's quad search works in 4 px tiles after
/// 2x decimation; a smaller image cannot hold a tag or a fruitlet and crashes the detector.
inline constexpr int kMinImageSidePx = 32;
/// Largest image side: 16384 px (beyond any stereo camera; bounds memory per frame).
inline constexpr int kMaxImageSidePx = 16384;
/// Field of view a pinhole model may have along each axis: a focal length outside this
/// range is a unit mistake (metres or millimetres instead of pixels), not a lens.
inline constexpr double kMinFieldOfViewDeg = 1.0;
inline constexpr double kMaxFieldOfViewDeg = 170.0;
/// Stereo baselines from 1 mm (phone-size rigs) to 2 m.
inline constexpr double kMinBaselineM = 0.001;
inline constexpr double kMaxBaselineM = 2.0;
/// Poses of cameras and tags lie within 1 km of the world origin.
inline constexpr double kMaxPoseTranslationM = 1000.0;

/// "SOURCE: field 'FIELD': expected EXPECTED, got VALUE" as std::invalid_argument.
[[noreturn]] void failField(const std::string& source, const std::string& field,
                            const std::string& expected, const std::string& got);

/// Throws unless value is finite and lo <= value <= hi.
void checkNumber(double value, double lo, double hi, const std::string& source,
                 const std::string& field, const std::string& unit);

/// Image size in [kMinImageSidePx, kMaxImageSidePx]; fx, fy giving a field of view in
/// [kMinFieldOfViewDeg, kMaxFieldOfViewDeg]; the principal point inside the image; the
/// baseline in [kMinBaselineM, kMaxBaselineM].
void checkIntrinsics(const StereoIntrinsics& intrinsics, const std::string& source);

/// Finite entries, a rotation (orthonormal within 1e-6, det +1) and a translation within
/// kMaxPoseTranslationM of the origin.
void checkPose(const Eigen::Isometry3d& T, const std::string& source, const std::string& field);

}  // namespace fvp::host
