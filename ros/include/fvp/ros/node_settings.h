// The fvp node's settings from its private ROS parameters (docs/ros.md, "Parameters"). The
// run's settings have the keys of the library's run specification (host/nbv/run_fields.h:
// planner, seed, planner_config, engine, backend, stop, budget_s, ...), the same names as
// result.json's "settings" and the Python keywords, and the configs are the CLI's YAML files;
// the rest say where the robot's topics and frames are. C++17.
#pragma once

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "fvp/host/nbv/nbv_setup.h"
#include "fvp/ros/joint_trajectory_commander.h"
#include "fvp/ros/stereo_topic_camera.h"

namespace fvp::ros {

struct FvpNodeSettings {
  host::nbv::NbvSetupOptions setup;  ///< the run's settings, perception and sizing
  StereoTopicCameraOptions camera;
  std::string joint_states_topic = "/joint_states";
  std::vector<std::string> joint_names;  ///< ArmModel's order; defaultJointNames()
  JointTrajectoryCommanderOptions commander;
  std::filesystem::path arm_config;  ///< empty: the built-in arm (robot/config/arm_default.yaml)
  /// Motion planning that repeats (MotionPlanner::setReproducible with this seed): for the
  /// simulator's runs that are compared with the library's at `fvp run --clock fixed`.
  std::optional<std::uint64_t> reproducible_motion_seed;
};

/// Reads every setting the private node handle has; absent ones keep their defaults. Throws
/// std::invalid_argument naming the parameter and what was expected ("parameter '~budget_s':
/// expected a finite number > 0, got -1"), and for settings the library refuses.
FvpNodeSettings readNodeSettings(const ::ros::NodeHandle& private_node);

/// A parameter by its key under the node's namespace: false when it is not set.
using ParamLookup = std::function<bool(const std::string& key, XmlRpc::XmlRpcValue& value)>;
/// The same from any lookup (tests use a map).
FvpNodeSettings readNodeSettings(const ParamLookup& lookup);

}  // namespace fvp::ros
