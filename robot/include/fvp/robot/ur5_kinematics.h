// UR5 kinematics with the standard DH parameters of Universal Robots: forward kinematics and
// the analytic inverse (Hawkins 2013, "Analytic inverse kinematics for the Universal Robots
// UR-5/UR-10 arms"), all up to 8 solutions. Frames: the base frame of the DH table (z up the
// base axis), the flange frame tool0 (z out of the flange).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <numbers>

namespace fvp::robot {

class Ur5Kinematics {
 public:
  using Joints = Eigen::Matrix<double, 6, 1>;
  static constexpr int kMaxSolutions = 8;
  // Standard DH table (a_i, alpha_i, d_i), joint i rotating about z_{i-1}.
  static constexpr std::array<double, 6> kD_m = {0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823};
  static constexpr std::array<double, 6> kA_m = {0.0, -0.425, -0.39225, 0.0, 0.0, 0.0};
  static constexpr std::array<double, 6> kAlpha_rad = {
      std::numbers::pi / 2, 0.0, 0.0, std::numbers::pi / 2, -std::numbers::pi / 2, 0.0};

  /// One DH link transform T_{i-1,i} for joint i (0-based) at angle theta.
  static Eigen::Isometry3d linkTransform(int i, double theta_rad);
  /// T_base_flange; `frames`, when given, receives T_base_i for i = 1..6 (frames[5] = flange).
  static Eigen::Isometry3d forward(const Joints& q_rad,
                                   std::array<Eigen::Isometry3d, 6>* frames = nullptr);
  /// Every analytic solution for T_base_flange, each angle in (-pi, pi]; returns how many
  /// (0 when the pose is out of reach). Where the wrist is singular (sin q5 ~ 0) q6 is set
  /// to 0 and q4 absorbs the rotation.
  static int inverse(const Eigen::Isometry3d& T_base_flange,
                     std::array<Joints, kMaxSolutions>& solutions);
};

}  // namespace fvp::robot
