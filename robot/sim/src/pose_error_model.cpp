#include "fvp/robot/sim/pose_error_model.h"

#include <cmath>
#include <numbers>
#include <random>

namespace fvp::robot::sim {
namespace {

// Streams of their own: "pose" and "view" in ASCII, so that the draws neither repeat the
// world generator's (same seed) nor each other's.
constexpr std::uint64_t kPoseStream = 0x706f7365, kViewStream = 0x76696577;

double radians(double deg) {
  return deg * std::numbers::pi / 180.0;
}

/// A rotation whose rotation vector has independent N(0, sigma^2) components.
Eigen::Matrix3d smallRotation(std::mt19937_64& rng, double sigma_rad) {
  if (!(sigma_rad > 0.0)) return Eigen::Matrix3d::Identity();
  std::normal_distribution<double> n(0.0, sigma_rad);
  const Eigen::Vector3d w(n(rng), n(rng), n(rng));
  const double angle = w.norm();
  return angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                     : Eigen::Matrix3d::Identity();
}

Eigen::Vector3d gaussianVector(std::mt19937_64& rng, double sigma) {
  if (!(sigma > 0.0)) return Eigen::Vector3d::Zero();
  std::normal_distribution<double> n(0.0, sigma);
  return {n(rng), n(rng), n(rng)};
}

}  // namespace

PoseErrorModel::PoseErrorModel(const WorldConfig& c, std::uint64_t seed)
    : seed_(seed),
      view_translation_sigma_m_(c.view_translation_sigma_m),
      view_rotation_sigma_rad_(radians(c.view_rotation_sigma_deg)) {
  enabled_ = c.hand_eye_translation_sigma_m > 0.0 || c.hand_eye_rotation_sigma_deg > 0.0 ||
             c.arm_position_error_m > 0.0 || c.view_translation_sigma_m > 0.0 ||
             c.view_rotation_sigma_deg > 0.0;
  std::seed_seq seq{seed, kPoseStream};
  std::mt19937_64 rng(seq);
  hand_eye_.linear() = smallRotation(rng, radians(c.hand_eye_rotation_sigma_deg));
  hand_eye_.translation() = gaussianVector(rng, c.hand_eye_translation_sigma_m);
  // Three waves of amplitude components N(0, 2/3 sigma^2): sin^2 averages 1/2, so each axis
  // has variance 3 * (2/3) sigma^2 / 2 = sigma^2 over positions and draws.
  std::uniform_real_distribution<double> phase(0.0, 2.0 * std::numbers::pi);
  for (Wave& w : waves_) {
    w.amplitude_m = gaussianVector(rng, std::sqrt(2.0 / 3.0) * c.arm_position_error_m);
    Eigen::Vector3d d = gaussianVector(rng, 1.0);
    w.direction = d.norm() > 0.0 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::UnitX();
    w.phase_rad = phase(rng);
  }
}

Eigen::Vector3d PoseErrorModel::armError_m(const Eigen::Vector3d& p_world_m) const {
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  for (const Wave& w : waves_)
    e += w.amplitude_m *
         std::sin(2.0 * std::numbers::pi * w.direction.dot(p_world_m) / kArmErrorWavelengthM +
                  w.phase_rad);
  return e;
}

Eigen::Isometry3d PoseErrorModel::viewNoise(int view) const {
  Eigen::Isometry3d n = Eigen::Isometry3d::Identity();
  if (!(view_translation_sigma_m_ > 0.0) && !(view_rotation_sigma_rad_ > 0.0)) return n;
  std::seed_seq seq{seed_, kViewStream, static_cast<std::uint64_t>(view)};
  std::mt19937_64 rng(seq);
  n.linear() = smallRotation(rng, view_rotation_sigma_rad_);
  n.translation() = gaussianVector(rng, view_translation_sigma_m_);
  return n;
}

Eigen::Isometry3d PoseErrorModel::truePose(const Eigen::Isometry3d& T_world_camera_told,
                                           int view) const {
  if (!enabled_) return T_world_camera_told;
  Eigen::Isometry3d arm = Eigen::Isometry3d::Identity();
  arm.translation() = armError_m(T_world_camera_told.translation());
  return arm * T_world_camera_told * hand_eye_ * viewNoise(view);
}

}  // namespace fvp::robot::sim
