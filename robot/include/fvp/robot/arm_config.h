// Parameters of the arm (docs/design.md section 7): the slider's placement relative to the
// simulated tree, the UR5's limits, the hand-eye transform, collision geometry, motion
// planning (and its reproducible budgets) and the workspace tree; the simulated clock is the
// simulator's (robot/sim/sim_clock.h). Every field is a YAML key of the
// same name, documented in robot/config/arm_default.yaml and docs/robot.md.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace fvp::robot {

// Slider: travel along world x, centred in front of the tree on its start-view (-y) side,
// at the height of a cart top, so every generated cluster (x within +-0.45 m, z 0.95-1.15 m)
// is reached with the shoulder at about the cluster's height.
inline constexpr double kDefaultSliderTravelM = 1.2;
inline const Eigen::Vector3d kDefaultSliderOriginM{0.0, -0.7, 0.75};
inline constexpr double kDefaultSliderYawDeg = 0.0;
inline constexpr double kDefaultBaseYawDeg = 90.0;
inline constexpr double kDefaultSliderMaxVelocityMS = 0.5;
inline constexpr double kDefaultSliderMaxAccelerationMS2 = 1.0;
// UR5 (CB3 datasheet): +-360 deg on every joint, 180 deg/s. The elbow is held to +-180 deg as
// ur_description does (beyond that the arm folds into itself). The datasheet gives no joint
// acceleration; 1.4 rad/s^2 is URScript's movej default.
inline constexpr double kDefaultJointLimitRad = 2.0 * double(EIGEN_PI);
inline constexpr double kDefaultElbowLimitRad = double(EIGEN_PI);
inline constexpr double kDefaultJointMaxVelocityRadS = double(EIGEN_PI);
inline constexpr double kDefaultJointMaxAccelerationRadS2 = 1.4;
// Hand-eye: left camera 2.5 cm left of the flange axis (half the 5 cm baseline), 6 cm out.
inline const Eigen::Vector3d kDefaultHandEyeTranslationM{-0.025, 0.0, 0.06};
inline const Eigen::Vector3d kDefaultHandEyeRpyDeg{0.0, 0.0, 0.0};
inline constexpr double kDefaultCameraBodyRadiusM = 0.03;
inline constexpr double kDefaultCollisionPaddingM = 0.01;
inline constexpr double kDefaultGroundZM = 0.0;
inline constexpr int kDefaultIkSliderSamples = 25;
inline constexpr const char* kDefaultPlanner = "RRTConnect";
inline constexpr const char* kDefaultTrajectoryTiming = "blended";
inline constexpr double kDefaultPlanningTimeS = 1.0;
inline constexpr double kDefaultSimplifyTimeS = 0.1;
// About the checks planning_time_s and simplify_time_s allow at the measured rate of
// BM_MotionPlan (docs/robot.md: validity checks per second on a 2-core AMD EPYC).
inline constexpr std::int64_t kDefaultReproduciblePlanningChecks = 660000;
inline constexpr std::int64_t kDefaultReproducibleSimplifyChecks = 66000;
// A 0.01 rad joint-space step moves no point of the arm more than ~1.7 cm (levers of up to
// ~1.2 m over seven joints), so a state between two checked ones is within ~0.85 cm of one:
// inside the 1 cm padding, the real (unpadded) arm never touches an occupied voxel.
inline constexpr double kDefaultValidityStepRad = 0.01;
/// Off until measured on more worlds (docs/robot.md "Going back the way in").
inline constexpr double kDefaultRetreatShare = 0.0;
inline constexpr std::int64_t kDefaultWorkspaceSamples = 10'000'000;  // the paper's
inline constexpr double kDefaultWorkspaceResolutionM = 0.04;
inline constexpr int kDefaultWorkspaceDirectionBins = 3;
inline constexpr int kDefaultWorkspaceMinCount = 1;
inline constexpr std::int64_t kDefaultWorkspaceSeed = 1;
inline constexpr const char* kDefaultWorkspaceCacheDir = "";
// The farthest a camera gets from the shoulder: the UR5's reach (shoulder to flange, with
// every offset); the workspace tree adds the hand-eye offset and the camera body.
inline constexpr double kUr5ReachM = 0.425 + 0.39225 + 0.10915 + 0.09465 + 0.0823 + 0.089159;
// The most memory building the workspace tree may take (ArmConfig::workspaceTreeBytes): the
// resolution, direction bins and samples are each in range, but 5 mm with 16 bins asked for
// terabytes.
inline constexpr std::uint64_t kMaxWorkspaceTreeBytes = std::uint64_t{4} << 30;

struct ArmConfig {
  // Slider (joint 0, prismatic) and the UR5's mount on its carriage.
  double slider_travel_m = kDefaultSliderTravelM;  ///< carriage range [-travel/2, travel/2]
  Eigen::Vector3d slider_origin_m = kDefaultSliderOriginM;  ///< centre of travel, world frame
  double slider_yaw_deg = kDefaultSliderYawDeg;  ///< travel direction in the xy plane, from +x
  double base_yaw_deg = kDefaultBaseYawDeg;      ///< UR5 base about z, relative to the travel
  double slider_max_velocity_m_s = kDefaultSliderMaxVelocityMS;
  double slider_max_acceleration_m_s2 = kDefaultSliderMaxAccelerationMS2;
  // UR5 joints 1-6.
  double joint_limit_rad = kDefaultJointLimitRad;  ///< |q| limit of every joint but the elbow
  double elbow_limit_rad = kDefaultElbowLimitRad;
  double joint_max_velocity_rad_s = kDefaultJointMaxVelocityRadS;
  double joint_max_acceleration_rad_s2 = kDefaultJointMaxAccelerationRadS2;
  // Hand-eye: T_flange_camera (left camera, OpenCV optical frame), rotation as roll-pitch-yaw.
  Eigen::Vector3d hand_eye_translation_m = kDefaultHandEyeTranslationM;
  Eigen::Vector3d hand_eye_rpy_deg = kDefaultHandEyeRpyDeg;
  // Collision geometry.
  double camera_body_radius_m = kDefaultCameraBodyRadiusM;
  double collision_padding_m = kDefaultCollisionPaddingM;  ///< added to capsules vs the map
  double ground_z_m = kDefaultGroundZM;
  // Inverse kinematics and motion planning.
  int ik_slider_samples = kDefaultIkSliderSamples;  ///< slider positions tried along the travel
  std::string planner = kDefaultPlanner;            ///< OMPL geometric planner name
  double planning_time_s = kDefaultPlanningTimeS;
  double simplify_time_s = kDefaultSimplifyTimeS;
  /// Reproducible planning (MotionPlanner::setReproducible, fvp run --clock fixed): the
  /// budgets in validity checks that stand in for planning_time_s and simplify_time_s.
  std::int64_t reproducible_planning_checks = kDefaultReproduciblePlanningChecks;
  std::int64_t reproducible_simplify_checks = kDefaultReproducibleSimplifyChecks;
  double validity_step_rad = kDefaultValidityStepRad;  ///< joint-space step of motion checks
  /// The share of the planning budget for going back the way the arm came in and planning
  /// from there, when the plans from where it stands fail (0: never; MotionPlanner).
  double retreat_share = kDefaultRetreatShare;
  /// How a planned path is timed (trajectory.h): "rest_to_rest" stops at every waypoint;
  /// "blended" moves through the via points with parabolic blends, where the blended path is
  /// collision-free (else rest to rest).
  std::string trajectory_timing = kDefaultTrajectoryTiming;
  // Workspace tree.
  std::int64_t workspace_samples = kDefaultWorkspaceSamples;
  double workspace_resolution_m = kDefaultWorkspaceResolutionM;
  int workspace_direction_bins = kDefaultWorkspaceDirectionBins;  ///< per cube-face edge
  int workspace_min_count = kDefaultWorkspaceMinCount;
  std::int64_t workspace_seed = kDefaultWorkspaceSeed;
  std::string workspace_cache_dir = kDefaultWorkspaceCacheDir;  ///< "": no cache

  /// Reads a YAML file; missing keys keep their defaults; unknown keys, wrong types and
  /// out-of-range values throw std::invalid_argument naming the file and the key.
  static ArmConfig fromYamlFile(const std::filesystem::path& path);
  /// Throws std::invalid_argument naming the first bad key and its expected range.
  void validate(const std::string& source = "arm config") const;
  /// The memory WorkspaceTree::build takes for this config (its grids and samples), bytes.
  std::uint64_t workspaceTreeBytes() const;
  static const std::vector<std::string>& keyNames();
  /// The config as a JSON object text (for result.json).
  std::string toJson() const;
};

/// The planners MotionPlanner can build by name (ArmConfig::planner).
const std::vector<std::string>& knownPlanners();

}  // namespace fvp::robot
