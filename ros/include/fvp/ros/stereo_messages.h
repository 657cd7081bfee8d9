// One stereo pair as ROS 1 messages and back (docs/ros.md): what a stereo bag holds per stamp,
// what the simulator bridge publishes and what the fvp node's camera receives. C++17, as ROS 1's
// message headers are.
#pragma once

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>
#include <stereo_msgs/DisparityImage.h>

#include <Eigen/Geometry>
#include <string>

#include "fvp/host/perception/capture.h"
#include "fvp/ros/stereo_bag.h"

namespace fvp::ros {

/// One stamp's messages of a stereo pair; mask and disparity are optional.
struct StereoMessages {
  sensor_msgs::Image::ConstPtr left, right, mask;
  stereo_msgs::DisparityImage::ConstPtr disparity;
  sensor_msgs::CameraInfo::ConstPtr left_info, right_info;
};

/// The capture's pair as messages with `header` (its stamp and the left camera's frame): both
/// images bgr8, both camera infos (rectified: the right one's P[3] = -fx * baseline), and the
/// mask (mono8, or mono16 for instance ids) and disparity (32FC1) when the capture has them.
StereoMessages stereoMessagesOf(const host::Capture& capture, const std_msgs::Header& header);

/// The pair as a capture placed at T_world_camera: images converted to bgr8, intrinsics from the
/// camera infos (the baseline from the right one's P), the mask and the disparity when present.
/// Throws std::runtime_error starting with `source` (a bag's path, a node's name), naming the
/// topic, the stamp and the field, for messages that do not make a pair.
host::Capture captureOfMessages(const StereoMessages& messages,
                                const Eigen::Isometry3d& T_world_camera,
                                const StereoBagTopics& topics, const std::string& source);

geometry_msgs::TransformStamped transformMsg(const Eigen::Isometry3d& T_parent_child,
                                             const std_msgs::Header& parent,
                                             const std::string& child_frame);
Eigen::Isometry3d isometryOf(const geometry_msgs::Transform& transform);
geometry_msgs::Point pointMsg(const Eigen::Vector3d& p);
geometry_msgs::Pose poseMsg(const Eigen::Isometry3d& T);

/// tf2 keeps frame ids without a leading '/' (ROS 1's old style) and refuses to look one up.
std::string frameId(const std::string& id);
/// "12.345 s", for errors.
std::string stampText(const ::ros::Time& stamp);

}  // namespace fvp::ros
