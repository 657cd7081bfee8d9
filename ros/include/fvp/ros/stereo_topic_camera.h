// The next-best-view loop's camera over ROS (docs/ros.md): a rectified stereo pair with its camera
// infos from topics (stereo_image_proc's names by default), optionally the robot's own fruitlet
// mask and disparity, and T_world_camera from tf at the left image's stamp. Each capture takes the
// first complete pair stamped after it was asked for, so a frame never shows the arm in motion;
// a triggered camera (the paper's flash stereo head, the simulator bridge) is triggered first.
// A pair that does not come, or cannot be placed by tf, is a dropped frame. C++17.
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <ros/subscriber.h>
#include <tf2_ros/buffer.h>

#include <condition_variable>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "fvp/host/nbv/camera.h"
#include "fvp/ros/stereo_messages.h"

namespace fvp::ros {

struct StereoTopicCameraOptions {
  StereoBagTopics topics;      ///< images, camera infos and the world frame
  bool use_mask = false;       ///< wait for topics.fruitlet_mask of each pair's stamp
  bool use_disparity = false;  ///< wait for topics.disparity of each pair's stamp
  /// A std_msgs/Header published to trigger each capture; empty: a free-running camera.
  std::string trigger_topic;
  double timeout_s = 5.0;     ///< wall seconds a capture waits for its pair before it drops
  double tf_timeout_s = 1.0;  ///< wall seconds it waits for tf at the pair's stamp
  void validate() const;      ///< throws std::invalid_argument naming the field
};

class StereoTopicCamera : public host::nbv::Camera {
 public:
  /// `tf` must outlive the camera (a tf2_ros::Buffer filled by a TransformListener).
  StereoTopicCamera(::ros::NodeHandle& node, const tf2_ros::Buffer& tf,
                    StereoTopicCameraOptions options);

  /// T_world_camera is not used: the frame's pose is tf's at the image stamp.
  host::nbv::CaptureResult capture(const Eigen::Isometry3d& T_world_camera) override;

 private:
  template <typename M>
  void subscribe(::ros::NodeHandle& node, const std::string& topic,
                 void (StereoTopicCamera::*store)(const typename M::ConstPtr&));
  void onLeft(const sensor_msgs::Image::ConstPtr& m);
  void onRight(const sensor_msgs::Image::ConstPtr& m);
  void onMask(const sensor_msgs::Image::ConstPtr& m);
  void onLeftInfo(const sensor_msgs::CameraInfo::ConstPtr& m);
  void onRightInfo(const sensor_msgs::CameraInfo::ConstPtr& m);
  void onDisparity(const stereo_msgs::DisparityImage::ConstPtr& m);
  /// Keeps `message` under its stamp and wakes capture (mutex_ not held).
  template <typename Store>
  void keep(const ::ros::Time& stamp, Store store);
  bool completeAtOrAfter(const ::ros::Time& after, ::ros::Time& stamp) const;  // mutex_ held
  /// tf's T_world_camera of `frame` at `stamp`, waiting up to tf_timeout_s of wall time.
  bool poseAt(const std::string& frame, const ::ros::Time& stamp, Eigen::Isometry3d& T_world_camera,
              std::string& why) const;

  const tf2_ros::Buffer& tf_;
  StereoTopicCameraOptions options_;
  std::string source_;  ///< the node's name, for errors
  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  std::map<::ros::Time, StereoMessages> pending_;
  bool capturing_ = false;  ///< a capture waits for a pair stamped at or after after_
  ::ros::Time after_;
  ::ros::Time consumed_;  ///< the last pair's stamp: each pair is captured once
  sensor_msgs::CameraInfo::ConstPtr latest_left_info_, latest_right_info_;
  std::vector<::ros::Subscriber> subscribers_;
  ::ros::Publisher trigger_;
};

}  // namespace fvp::ros
