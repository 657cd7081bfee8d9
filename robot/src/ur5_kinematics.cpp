#include "fvp/robot/ur5_kinematics.h"

#include <algorithm>
#include <cmath>

namespace fvp::robot {
namespace {

constexpr double kPi = std::numbers::pi;
// Tolerance on |cos| slightly above 1 from rounding at the workspace boundary.
constexpr double kCosSlack = 1e-9;

double wrapAngle(double a) {
  a = std::remainder(a, 2.0 * kPi);  // [-pi, pi]
  return a <= -kPi ? a + 2.0 * kPi : a;
}

}  // namespace

Eigen::Isometry3d Ur5Kinematics::linkTransform(int i, double theta_rad) {
  const double ct = std::cos(theta_rad), st = std::sin(theta_rad);
  const double ca = std::cos(kAlpha_rad[i]), sa = std::sin(kAlpha_rad[i]);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << ct, -st * ca, st * sa,  //
      st, ct * ca, -ct * sa,            //
      0.0, sa, ca;
  T.translation() << kA_m[i] * ct, kA_m[i] * st, kD_m[i];
  return T;
}

Eigen::Isometry3d Ur5Kinematics::forward(const Joints& q_rad,
                                         std::array<Eigen::Isometry3d, 6>* frames) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 6; ++i) {
    T = T * linkTransform(i, q_rad[i]);
    if (frames != nullptr) (*frames)[i] = T;
  }
  return T;
}

int Ur5Kinematics::inverse(const Eigen::Isometry3d& T_base_flange,
                           std::array<Joints, kMaxSolutions>& solutions) {
  const double d4 = kD_m[3], d6 = kD_m[5], a2 = kA_m[1], a3 = kA_m[2];
  const Eigen::Matrix3d& R = T_base_flange.linear();
  const Eigen::Vector3d p = T_base_flange.translation();
  int count = 0;

  // q1: the wrist centre (frame 5's origin) lies d4 off the plane of the arm.
  const Eigen::Vector3d p05 = p - d6 * R.col(2);
  const double r05 = std::hypot(p05.x(), p05.y());
  if (r05 < std::abs(d4)) return 0;
  const double psi = std::atan2(p05.y(), p05.x());
  const double phi = std::acos(std::clamp(d4 / r05, -1.0, 1.0));
  for (const double q1 : {psi + phi + kPi / 2, psi - phi + kPi / 2}) {
    const double s1 = std::sin(q1), c1 = std::cos(q1);
    // q5: the flange position across the arm's plane is d4 + d6 cos q5.
    const double c5 = (p.x() * s1 - p.y() * c1 - d4) / d6;
    if (std::abs(c5) > 1.0 + kCosSlack) continue;
    const double q5_abs = std::acos(std::clamp(c5, -1.0, 1.0));
    for (const double q5 : {q5_abs, -q5_abs}) {
      const double s5 = std::sin(q5);
      double q6 = 0.0;
      if (std::abs(s5) > 1e-10) {
        q6 = std::atan2((-R(0, 1) * s1 + R(1, 1) * c1) / s5, (R(0, 0) * s1 - R(1, 0) * c1) / s5);
      }
      // Frames 1..4: the planar two-link problem for q2, q3, then q4 closes the rotation.
      const Eigen::Isometry3d T14 = linkTransform(0, q1).inverse() * T_base_flange *
                                    linkTransform(5, q6).inverse() * linkTransform(4, q5).inverse();
      const Eigen::Vector3d p13 = T14 * Eigen::Vector3d(0.0, -d4, 0.0);
      const double r13_sq = p13.x() * p13.x() + p13.y() * p13.y();
      const double c3 = (r13_sq - a2 * a2 - a3 * a3) / (2.0 * a2 * a3);
      if (std::abs(c3) > 1.0 + kCosSlack) continue;
      const double q3_abs = std::acos(std::clamp(c3, -1.0, 1.0));
      for (const double q3 : {q3_abs, -q3_abs}) {
        const double q2 =
            std::atan2(p13.y(), p13.x()) - std::atan2(a3 * std::sin(q3), a2 + a3 * std::cos(q3));
        const Eigen::Isometry3d T34 = (linkTransform(1, q2) * linkTransform(2, q3)).inverse() * T14;
        const double q4 = std::atan2(T34(1, 0), T34(0, 0));
        Joints& q = solutions[count++];
        q << wrapAngle(q1), wrapAngle(q2), wrapAngle(q3), wrapAngle(q4), wrapAngle(q5),
            wrapAngle(q6);
      }
    }
  }
  return count;
}

}  // namespace fvp::robot
