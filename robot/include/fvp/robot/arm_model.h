// The 7-joint arm: a prismatic slider (joint 0, metres) carrying a UR5 (joints 1-6,
// radians), with the hand-eye transform to the left camera (OpenCV optical frame: x right,
// y down, z forward). Forward and inverse kinematics in the world frame, joint limits, link
// capsules and the checks that need no map (self collision, ground, slider rail).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "fvp/robot/arm_config.h"
#include "fvp/robot/capsule.h"

namespace fvp::robot {

inline constexpr int kArmJoints = 7;
using JointVector = Eigen::Matrix<double, kArmJoints, 1>;

/// Capsules, in this order: base column, upper arm, forearm, wrist 1, wrist 2, wrist 3,
/// camera body.
inline constexpr int kLinkCount = 7;
inline constexpr int kCameraLink = 6;
using LinkCapsules = std::array<Capsule, kLinkCount>;

class ArmModel {
 public:
  /// Throws std::invalid_argument for an invalid config.
  explicit ArmModel(const ArmConfig& config);

  const ArmConfig& config() const { return config_; }
  const JointVector& lowerLimits() const { return lower_; }
  const JointVector& upperLimits() const { return upper_; }
  const JointVector& maxVelocity() const { return max_velocity_; }
  const JointVector& maxAcceleration() const { return max_acceleration_; }
  const Eigen::Isometry3d& T_flange_camera() const { return T_flange_camera_; }
  /// The UR5 base frame in the world for a slider position.
  Eigen::Isometry3d T_world_base(double slider_m) const;
  Eigen::Isometry3d T_world_camera(const JointVector& q) const;
  /// The link capsules (and, when asked, the camera pose from the same forward pass).
  /// An upper bound on how far any point of the arm's capsules (surfaces included) moves
  /// when the joints move by dq, in any way: sum_j reach_j * |dq_j|, with reach_j the
  /// farthest any capsule point can lie from joint j's axis (1 for the slider, in metres
  /// per metre). Motion checks use it to keep the sweep between two checks inside the
  /// collision padding.
  double sweepBound_m(const JointVector& dq) const;
  LinkCapsules linkCapsules(const JointVector& q,
                            Eigen::Isometry3d* T_world_camera = nullptr) const;

  bool withinLimits(const JointVector& q) const;
  /// Link against link (pairs that cannot touch through a shared joint), links against the
  /// ground plane and the slider rail. Radii unpadded: this is the robot's own geometry.
  bool selfOrStaticCollision(const LinkCapsules& links) const;

  /// Every IK solution for the camera pose at one slider position that is within the
  /// joint limits; of the 2*pi-equivalent angles of each joint, the one nearest `near`.
  void inverseAt(const Eigen::Isometry3d& T_world_camera, double slider_m, const JointVector& near,
                 std::vector<JointVector>& out) const;
  /// Solutions over ik_slider_samples slider positions spread over the travel plus near's
  /// own, sorted by travelTime_s from `near` (soonest first; joint-space distance breaks
  /// ties). Map collisions are the caller's (ArmCollisionChecker) to check.
  std::vector<JointVector> inverse(const Eigen::Isometry3d& T_world_camera,
                                   const JointVector& near) const;
  /// The duration of the straight rest-to-rest motion between two configurations under the
  /// joint limits (Trajectory's timing): what the slowest joint needs, the least a move
  /// between them costs. The arm's "nearness" for choosing among IK solutions.
  double travelTime_s(const JointVector& from, const JointVector& to) const;
  /// Whether any solution within limits and free of self/static collision exists.
  bool reachableByIk(const Eigen::Isometry3d& T_world_camera) const;
  /// A configuration near the middle of every joint range (slider centred, arm up).
  JointVector homeConfiguration() const;

 private:
  ArmConfig config_;
  JointVector lower_, upper_, max_velocity_, max_acceleration_;
  Eigen::Isometry3d T_flange_camera_, T_camera_flange_;
  Eigen::Vector3d slider_dir_;
  Eigen::Matrix3d R_world_base_;
  Capsule rail_;
};

/// Weighted joint-space distance used to pick the nearest IK solution (metres of slider
/// count as radians).
inline double jointDistance(const JointVector& a, const JointVector& b) {
  return (a - b).norm();
}

}  // namespace fvp::robot
