// The errors between the pose a robot is told its camera has and the pose the camera really
// has (docs/simulation.md, "Pose errors"): a fixed hand-eye calibration error per trial, the
// uncalibrated arm's smooth position-dependent positioning error, and per-view repeatability
// noise. The simulated camera renders from the true pose and reports the told one, as a real
// robot's forward kinematics and calibration would. Deterministic per seed; all zero by
// default (the paper's exact poses).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>

#include "fvp/robot/sim/world_config.h"

namespace fvp::robot::sim {

class PoseErrorModel {
 public:
  /// The wavelength of the arm's position error: a joint offset's effect on the camera
  /// changes over a fraction of a turn, about half a metre of travel of the UR5's 0.4 m links.
  static constexpr double kArmErrorWavelengthM = 0.5;

  /// The magnitudes from config (hand_eye_*, arm_position_error_m, view_*); the random
  /// draws from seed (a stream of its own: the world generated from the same seed is not
  /// changed by them).
  PoseErrorModel(const WorldConfig& config, std::uint64_t seed);

  /// Whether any error is on.
  bool enabled() const { return enabled_; }

  /// Where the camera really is for view `view` when the robot believes T_world_camera_told:
  /// T_true = A(p) * T_told * H * N_view, with H the hand-eye error (in the camera frame),
  /// A(p) the arm's position error at the told camera position p (a world-frame
  /// translation) and N_view the view's repeatability noise (in the camera frame).
  Eigen::Isometry3d truePose(const Eigen::Isometry3d& T_world_camera_told, int view) const;

  /// H: the camera's true mount in the frame the robot believes it has (fixed per trial).
  const Eigen::Isometry3d& T_camera_told_camera_true() const { return hand_eye_; }
  /// The arm's position error at a told camera position: a smooth field of per-axis RMS
  /// arm_position_error_m (three plane waves of kArmErrorWavelengthM).
  Eigen::Vector3d armError_m(const Eigen::Vector3d& p_world_m) const;
  /// The view's repeatability noise, in the camera frame.
  Eigen::Isometry3d viewNoise(int view) const;

 private:
  struct Wave {
    Eigen::Vector3d amplitude_m, direction;
    double phase_rad = 0.0;
  };
  bool enabled_ = false;
  std::uint64_t seed_ = 0;
  double view_translation_sigma_m_ = 0.0, view_rotation_sigma_rad_ = 0.0;
  Eigen::Isometry3d hand_eye_ = Eigen::Isometry3d::Identity();
  std::array<Wave, 3> waves_{};
};

}  // namespace fvp::robot::sim
