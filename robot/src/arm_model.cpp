#include "fvp/robot/arm_model.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "fvp/robot/trajectory.h"
#include "fvp/robot/ur5_kinematics.h"

namespace fvp::robot {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegToRad = kPi / 180.0;
// UR5 link radii (a little over the real tubes) and the lateral offsets of the upper arm and
// forearm from the DH plane (the DH table folds them into d4).
constexpr double kBaseRadiusM = 0.075;
constexpr double kUpperArmRadiusM = 0.065;
constexpr double kForearmRadiusM = 0.055;
constexpr double kWristRadiusM = 0.045;
constexpr double kShoulderOffsetM = 0.13585;
constexpr double kForearmOffsetM = 0.13585 - 0.1197;
// The camera rig: a bar along the camera x axis through both lenses (baseline 5 cm), set
// back 3 cm behind the left camera's optical centre.
constexpr double kBaselineM = 0.05;
constexpr double kCameraSetbackM = 0.03;
// The slider rail: a beam under the carriage, over the whole travel and a bit more.
constexpr double kRailRadiusM = 0.08;
constexpr double kRailOverhangM = 0.15;

// Pairs of links that may collide; adjacent links and the wrist chain (which touch by
// construction at their shared joints) are left out.
constexpr std::array<std::pair<int, int>, 10> kSelfPairs = {{
    {0, 2},
    {0, 3},
    {0, 4},
    {0, 5},
    {0, 6},
    {1, 3},
    {1, 4},
    {1, 5},
    {1, 6},
    {2, 6},
}};

Eigen::Matrix3d rpyToMatrix(const Eigen::Vector3d& rpy_deg) {
  return (Eigen::AngleAxisd(rpy_deg.z() * kDegToRad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy_deg.y() * kDegToRad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy_deg.x() * kDegToRad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace

ArmModel::ArmModel(const ArmConfig& config) : config_(config) {
  config_.validate();
  const double half_travel = 0.5 * config_.slider_travel_m;
  lower_ << -half_travel, -config_.joint_limit_rad, -config_.joint_limit_rad,
      -config_.elbow_limit_rad, -config_.joint_limit_rad, -config_.joint_limit_rad,
      -config_.joint_limit_rad;
  upper_ = -lower_;
  max_velocity_.setConstant(config_.joint_max_velocity_rad_s);
  max_velocity_[0] = config_.slider_max_velocity_m_s;
  max_acceleration_.setConstant(config_.joint_max_acceleration_rad_s2);
  max_acceleration_[0] = config_.slider_max_acceleration_m_s2;
  T_flange_camera_.setIdentity();
  T_flange_camera_.linear() = rpyToMatrix(config_.hand_eye_rpy_deg);
  T_flange_camera_.translation() = config_.hand_eye_translation_m;
  T_camera_flange_ = T_flange_camera_.inverse();
  const double yaw = config_.slider_yaw_deg * kDegToRad;
  slider_dir_ = Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
  R_world_base_ =
      Eigen::AngleAxisd(yaw + config_.base_yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  const Eigen::Vector3d rail_centre =
      config_.slider_origin_m - (kRailRadiusM + 0.005) * Eigen::Vector3d::UnitZ();
  rail_.a_m = rail_centre - (half_travel + kRailOverhangM) * slider_dir_;
  rail_.b_m = rail_centre + (half_travel + kRailOverhangM) * slider_dir_;
  rail_.radius_m = kRailRadiusM;
}

Eigen::Isometry3d ArmModel::T_world_base(double slider_m) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_world_base_;
  T.translation() = config_.slider_origin_m + slider_m * slider_dir_;
  return T;
}

Eigen::Isometry3d ArmModel::T_world_camera(const JointVector& q) const {
  return T_world_base(q[0]) * Ur5Kinematics::forward(q.tail<6>()) * T_flange_camera_;
}

double ArmModel::sweepBound_m(const JointVector& dq) const {
  // Farthest capsule point from each joint's axis: the UR5 links after the joint (DH a2 =
  // 0.425, a3 = 0.392, d4 = 0.109, d5 = 0.095, d6 = 0.082 m), the shoulder offset (0.136),
  // the camera (hand-eye offset, setback and baseline, <= 0.17) and the thickest capsule
  // radius after the joint, rounded up. tests/robot/arm_kinematics_test.cpp checks them.
  static constexpr double kReachM[kArmJoints] = {1.0, 1.5, 1.5, 1.05, 0.55, 0.45, 0.35};
  double bound = 0.0;
  for (int j = 0; j < kArmJoints; ++j) bound += kReachM[j] * std::abs(dq[j]);
  return bound;
}

LinkCapsules ArmModel::linkCapsules(const JointVector& q, Eigen::Isometry3d* T_world_camera) const {
  std::array<Eigen::Isometry3d, 6> frames;
  const Eigen::Isometry3d T_wb = T_world_base(q[0]);
  Ur5Kinematics::forward(q.tail<6>(), &frames);
  for (Eigen::Isometry3d& f : frames) f = T_wb * f;
  const Eigen::Vector3d base = T_wb.translation();
  // Joint 2's and 3's axes are z of frames 1 and 2: the real links sit off the DH plane
  // along them.
  const Eigen::Vector3d z1 = frames[0].linear().col(2), z2 = frames[1].linear().col(2);
  LinkCapsules links;
  links[0] = {base, frames[0].translation() + kShoulderOffsetM * z1, kBaseRadiusM};
  links[1] = {frames[0].translation() + kShoulderOffsetM * z1,
              frames[1].translation() + kShoulderOffsetM * z1, kUpperArmRadiusM};
  links[2] = {frames[1].translation() + kForearmOffsetM * z2,
              frames[2].translation() + kForearmOffsetM * z2, kForearmRadiusM};
  links[3] = {frames[2].translation(), frames[3].translation(), kWristRadiusM};
  links[4] = {frames[3].translation(), frames[4].translation(), kWristRadiusM};
  links[5] = {frames[4].translation(), frames[5].translation(), kWristRadiusM};
  const Eigen::Isometry3d T_wc = frames[5] * T_flange_camera_;
  links[6] = {T_wc * Eigen::Vector3d(0.0, 0.0, -kCameraSetbackM),
              T_wc * Eigen::Vector3d(kBaselineM, 0.0, -kCameraSetbackM),
              config_.camera_body_radius_m};
  if (T_world_camera != nullptr) *T_world_camera = T_wc;
  return links;
}

bool ArmModel::withinLimits(const JointVector& q) const {
  return (q.array() >= lower_.array()).all() && (q.array() <= upper_.array()).all();
}

bool ArmModel::selfOrStaticCollision(const LinkCapsules& links) const {
  for (const auto& [i, j] : kSelfPairs) {
    if (capsulesOverlap(links[i], links[j])) return true;
  }
  for (int i = 0; i < kLinkCount; ++i) {
    const Capsule& c = links[i];
    if (std::min(c.a_m.z(), c.b_m.z()) - c.radius_m < config_.ground_z_m) return true;
    // The base column stands on the carriage above the rail.
    if (i > 0 && capsulesOverlap(c, rail_)) return true;
  }
  return false;
}

void ArmModel::inverseAt(const Eigen::Isometry3d& T_world_camera, double slider_m,
                         const JointVector& near, std::vector<JointVector>& out) const {
  if (slider_m < lower_[0] || slider_m > upper_[0]) return;
  const Eigen::Isometry3d T_base_flange =
      T_world_base(slider_m).inverse() * T_world_camera * T_camera_flange_;
  std::array<Ur5Kinematics::Joints, Ur5Kinematics::kMaxSolutions> solutions;
  const int count = Ur5Kinematics::inverse(T_base_flange, solutions);
  for (int s = 0; s < count; ++s) {
    JointVector q;
    q[0] = slider_m;
    bool ok = true;
    for (int j = 1; j < kArmJoints && ok; ++j) {
      // Of angle + 2*pi*k, the one within limits nearest `near`.
      const double a = solutions[s][j - 1];
      const double k = std::round((near[j] - a) / (2.0 * kPi));
      double best = 0.0;
      bool found = false;
      for (const double kk : {k, k - 1.0, k + 1.0}) {
        const double v = a + 2.0 * kPi * kk;
        if (v < lower_[j] || v > upper_[j]) continue;
        if (!found || std::abs(v - near[j]) < std::abs(best - near[j])) best = v;
        found = true;
      }
      ok = found;
      q[j] = best;
    }
    if (ok) out.push_back(q);
  }
}

std::vector<JointVector> ArmModel::inverse(const Eigen::Isometry3d& T_world_camera,
                                           const JointVector& near) const {
  std::vector<JointVector> out;
  const int n = config_.ik_slider_samples;
  for (int i = 0; i < n; ++i) {
    const double t = n == 1 ? 0.5 : static_cast<double>(i) / (n - 1);
    inverseAt(T_world_camera, lower_[0] + t * (upper_[0] - lower_[0]), near, out);
  }
  inverseAt(T_world_camera, std::clamp(near[0], lower_[0], upper_[0]), near, out);
  // The move's duration is set by its slowest joint, which the Euclidean joint distance does
  // not see (a wrist turning 2 rad alone takes as long as the whole arm turning 2 rad).
  std::vector<std::pair<std::pair<double, double>, std::size_t>> keyed;
  keyed.reserve(out.size());
  for (std::size_t i = 0; i < out.size(); ++i)
    keyed.push_back({{travelTime_s(near, out[i]), jointDistance(near, out[i])}, i});
  std::sort(keyed.begin(), keyed.end());
  std::vector<JointVector> sorted;
  sorted.reserve(out.size());
  for (const auto& k : keyed) sorted.push_back(out[k.second]);
  return sorted;
}

double ArmModel::travelTime_s(const JointVector& from, const JointVector& to) const {
  return Trajectory::restToRestDuration_s(from, to, max_velocity_, max_acceleration_);
}

bool ArmModel::reachableByIk(const Eigen::Isometry3d& T_world_camera) const {
  for (const JointVector& q : inverse(T_world_camera, homeConfiguration())) {
    if (!selfOrStaticCollision(linkCapsules(q))) return true;
  }
  return false;
}

JointVector ArmModel::homeConfiguration() const {
  JointVector q;
  // Shoulder up, elbow bent, wrist facing forward: a typical UR5 "ready" pose.
  q << 0.0, 0.0, -kPi / 2, kPi / 2, -kPi / 2, -kPi / 2, 0.0;
  return q;
}

}  // namespace fvp::robot
