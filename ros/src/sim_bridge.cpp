#include "fvp/ros/sim_bridge.h"

#include <ros/console.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fvp/host/perception/capture.h"
#include "fvp/robot/sim/simulated_arm.h"
#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/robot/sim/world.h"
#include "fvp/ros/joint_state_listener.h"
#include "fvp/ros/stereo_messages.h"

namespace fvp::ros {

void SimBridgeOptions::validate() const {
  for (const auto& [topic, name] : {std::pair{&trigger_topic, "trigger_topic"},
                                    {&command_topic, "command_topic"},
                                    {&joint_states_topic, "joint_states_topic"},
                                    {&camera_frame, "camera_frame"}})
    if (topic->empty()) throw std::invalid_argument(std::string(name) + ": expected a name");
  if (!joint_names.empty() && joint_names.size() != std::size_t(robot::kArmJoints))
    throw std::invalid_argument("joint_names: expected 7 names (the slider, then the UR5's six)");
  if (!(publish_rate_hz > 0.0 && publish_rate_hz <= 1000.0))
    throw std::invalid_argument("publish_rate_hz: expected a rate in (0, 1000]");
}

SimBridge::SimBridge(::ros::NodeHandle& node, SimBridgeOptions options)
    : options_(std::move(options)) {
  options_.validate();
  if (options_.joint_names.empty()) options_.joint_names = defaultJointNames();
  robot_ = std::make_unique<trials::SimulatedRobot>(options_.robot);
  wall_mark_ = std::chrono::steady_clock::now();
  const StereoBagTopics& t = options_.topics;
  clock_ = node.advertise<rosgraph_msgs::Clock>("/clock", 10);
  joint_states_ = node.advertise<sensor_msgs::JointState>(options_.joint_states_topic, 10);
  left_ = node.advertise<sensor_msgs::Image>(t.left_image, 2);
  right_ = node.advertise<sensor_msgs::Image>(t.right_image, 2);
  left_info_ = node.advertise<sensor_msgs::CameraInfo>(t.left_info, 2);
  right_info_ = node.advertise<sensor_msgs::CameraInfo>(t.right_info, 2);
  mask_ = node.advertise<sensor_msgs::Image>(t.fruitlet_mask, 2);
  disparity_ = node.advertise<stereo_msgs::DisparityImage>(t.disparity, 2);
  trigger_ = node.subscribe(options_.trigger_topic, 4, &SimBridge::onTrigger, this);
  command_ = node.subscribe(options_.command_topic, 4, &SimBridge::onTrajectory, this);
}

SimBridge::~SimBridge() = default;

::ros::Time SimBridge::now() const {
  std::lock_guard<std::mutex> lock(clock_mutex_);
  const double wall_s =
      frozen_
          ? 0.0
          : std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_mark_).count();
  return ::ros::Time(base_s_ + wall_s);
}

::ros::Time SimBridge::freeze() {
  const ::ros::Time stopped = now();
  std::lock_guard<std::mutex> lock(clock_mutex_);
  base_s_ = stopped.toSec();
  frozen_ = true;
  return stopped;
}

void SimBridge::thaw(double charged_s) {
  {
    std::lock_guard<std::mutex> lock(clock_mutex_);
    base_s_ += charged_s;
    wall_mark_ = std::chrono::steady_clock::now();
    frozen_ = false;
  }
  publishStateAt(publishClock());
}

void SimBridge::publishState() {
  // During an event the event publishes the state, at its own stamps (tf refuses repeats),
  // and the joints are the event's to change.
  std::unique_lock<std::mutex> event(event_mutex_, std::try_to_lock);
  if (!event.owns_lock()) {
    publishClock();
    return;
  }
  publishStateAt(publishClock());
}

::ros::Time SimBridge::publishClock() {
  // Read and sent under one lock, and never older than what was sent: a stale read racing an
  // event's thaw would step the node's time back (tf2 drops its buffer on that).
  std::lock_guard<std::mutex> lock(publish_mutex_);
  const ::ros::Time stamp = std::max(now(), last_clock_);
  rosgraph_msgs::Clock clock;
  clock.clock = stamp;
  clock_.publish(clock);
  last_clock_ = stamp;
  return stamp;
}

void SimBridge::publishStateAt(const ::ros::Time& stamp) {
  if (stamp <= last_state_stamp_) return;  // tf refuses a stamp it has
  last_state_stamp_ = stamp;
  const robot::JointVector q = robot_->simulatedArm().joints();
  sensor_msgs::JointState state;
  state.header.stamp = stamp;
  state.name = options_.joint_names;
  state.position.assign(q.data(), q.data() + q.size());
  joint_states_.publish(state);
  std_msgs::Header world;
  world.stamp = stamp;
  world.frame_id = options_.topics.world_frame;
  tf_.sendTransform(
      transformMsg(robot_->simulatedArm().cameraPose(), world, options_.camera_frame));
}

void SimBridge::onTrigger(const std_msgs::Header::ConstPtr&) {
  std::lock_guard<std::mutex> event(event_mutex_);
  const ::ros::Time stamp = freeze();
  const double before_s = robot_->clock().now_s();
  try {
    capture(stamp);
  } catch (const std::exception& e) {  // the renderer or cv_bridge failed: no pair, time runs on
    ROS_ERROR_STREAM("simulated camera failed: " << e.what());
  }
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.captures;
  }
  thaw(robot_->clock().now_s() - before_s);
}

void SimBridge::capture(const ::ros::Time& stamp) {
  robot::sim::SimulatedCamera& camera = robot_->camera();
  const host::nbv::CaptureResult result = camera.capture(robot_->simulatedArm().cameraPose());
  if (result.ok()) {
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = options_.camera_frame;
    const host::Capture capture = host::captureOfFrame(result.frame);
    const StereoMessages m = stereoMessagesOf(capture, header);
    std_msgs::Header world = header;
    world.frame_id = options_.topics.world_frame;
    // The pose first: the node looks tf up at the images' stamp as they arrive.
    if (stamp > last_state_stamp_) {
      tf_.sendTransform(transformMsg(capture.T_world_camera, world, options_.camera_frame));
      last_state_stamp_ = stamp;
    }
    left_info_.publish(m.left_info);
    right_info_.publish(m.right_info);
    if (m.mask) mask_.publish(m.mask);
    if (m.disparity) disparity_.publish(m.disparity);
    left_.publish(m.left);
    right_.publish(m.right);
  } else {
    ROS_WARN_STREAM("simulated camera dropped a frame: " << result.detail);
  }
}

std::string SimBridge::check(const trajectory_msgs::JointTrajectory& t, double& duration_s,
                             robot::JointVector& end) const {
  if (t.points.empty()) return "no points";
  std::vector<int> column(options_.joint_names.size(), -1);
  for (std::size_t i = 0; i < t.joint_names.size(); ++i) {
    const auto it =
        std::find(options_.joint_names.begin(), options_.joint_names.end(), t.joint_names[i]);
    if (it == options_.joint_names.end())
      return "joint '" + t.joint_names[i] + "' is not the arm's";
    column[std::size_t(it - options_.joint_names.begin())] = int(i);
  }
  for (std::size_t j = 0; j < column.size(); ++j)
    if (column[j] < 0) return "joint '" + options_.joint_names[j] + "' is missing";
  double previous_s = 0.0;
  for (const trajectory_msgs::JointTrajectoryPoint& p : t.points) {
    if (p.positions.size() != t.joint_names.size())
      return "a point's positions: expected one per joint";
    for (const double x : p.positions)
      if (!std::isfinite(x)) return "a position is not finite";
    const double s = p.time_from_start.toSec();
    if (s < previous_s) return "time_from_start goes backwards";
    previous_s = s;
  }
  for (std::size_t j = 0; j < column.size(); ++j)
    end[Eigen::Index(j)] = t.points.back().positions[std::size_t(column[j])];
  if (!robot_->simulatedArm().planned().model().withinLimits(end))
    return "its end is outside the arm's joint limits";
  duration_s = previous_s;
  return {};
}

void SimBridge::onTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& trajectory) {
  double duration_s = 0.0;
  robot::JointVector end;
  if (const std::string why = check(*trajectory, duration_s, end); !why.empty()) {
    // A controller refuses such a trajectory and the arm stays: the node times out.
    ROS_ERROR_STREAM("refused a joint trajectory on " << options_.command_topic << ": " << why);
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.rejected_trajectories;
    return;
  }
  std::lock_guard<std::mutex> event(event_mutex_);
  freeze();
  const double before_s = robot_->clock().now_s();
  robot_->simulatedArm().runSentMotion(duration_s, end);  // checked: cannot throw
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.trajectories;
  }
  thaw(robot_->clock().now_s() - before_s);
}

std::vector<std::vector<double>> SimBridge::clusterTable() const {
  std::vector<std::vector<double>> table;
  for (const robot::sim::FruitletCluster& c : robot_->world().clusters()) {
    const Eigen::Isometry3d& T = c.T_world_start_camera;
    const Eigen::Quaterniond q(T.linear());
    table.push_back({double(c.tag.tag_id), T.translation().x(), T.translation().y(),
                     T.translation().z(), q.x(), q.y(), q.z(), q.w(), c.center_m.x(),
                     c.center_m.y(), c.center_m.z()});
  }
  return table;
}

SimBridgeStats SimBridge::stats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return stats_;
}

}  // namespace fvp::ros
