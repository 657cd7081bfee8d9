#include "fvp/ros/stereo_topic_camera.h"

#include <ros/this_node.h>
#include <std_msgs/Header.h>
#include <tf2/exceptions.h>

#include <chrono>
#include <stdexcept>
#include <thread>

#include "fvp/host/perception/capture.h"

namespace fvp::ros {
namespace {

/// Stamps kept: while a capture waits, the first ones at or after its request (a mask or a
/// disparity computed later still finds its pair); between captures, the newest. A bound on
/// memory: each holds a pair of images.
constexpr std::size_t kKeptStamps = 8;

}  // namespace

void StereoTopicCameraOptions::validate() const {
  for (const std::string* topic :
       {&topics.left_image, &topics.right_image, &topics.left_info, &topics.right_info})
    if (topic->empty())
      throw std::invalid_argument("stereo topics: expected every image and info topic");
  if (use_mask && topics.fruitlet_mask.empty())
    throw std::invalid_argument("mask_topic: expected a topic with use_mask");
  if (use_disparity && topics.disparity.empty())
    throw std::invalid_argument("disparity_topic: expected a topic with use_disparity");
  if (topics.world_frame.empty()) throw std::invalid_argument("world_frame: expected a frame");
  if (!(timeout_s > 0.0)) throw std::invalid_argument("capture_timeout_s: expected seconds > 0");
  if (!(tf_timeout_s >= 0.0)) throw std::invalid_argument("tf_timeout_s: expected seconds >= 0");
}

template <typename M>
void StereoTopicCamera::subscribe(::ros::NodeHandle& node, const std::string& topic,
                                  void (StereoTopicCamera::*store)(const typename M::ConstPtr&)) {
  subscribers_.push_back(node.subscribe<M>(topic, 4, store, this));
}

StereoTopicCamera::StereoTopicCamera(::ros::NodeHandle& node, const tf2_ros::Buffer& tf,
                                     StereoTopicCameraOptions options)
    : tf_(tf), options_(std::move(options)), source_(::ros::this_node::getName()) {
  options_.validate();
  const StereoBagTopics& t = options_.topics;
  subscribe<sensor_msgs::Image>(node, t.left_image, &StereoTopicCamera::onLeft);
  subscribe<sensor_msgs::Image>(node, t.right_image, &StereoTopicCamera::onRight);
  subscribe<sensor_msgs::CameraInfo>(node, t.left_info, &StereoTopicCamera::onLeftInfo);
  subscribe<sensor_msgs::CameraInfo>(node, t.right_info, &StereoTopicCamera::onRightInfo);
  if (options_.use_mask)
    subscribe<sensor_msgs::Image>(node, t.fruitlet_mask, &StereoTopicCamera::onMask);
  if (options_.use_disparity)
    subscribe<stereo_msgs::DisparityImage>(node, t.disparity, &StereoTopicCamera::onDisparity);
  if (!options_.trigger_topic.empty())
    trigger_ = node.advertise<std_msgs::Header>(options_.trigger_topic, 1);
}

template <typename Store>
void StereoTopicCamera::keep(const ::ros::Time& stamp, Store store) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = pending_.find(stamp);
    if (it == pending_.end()) {
      if (stamp <= consumed_ || (capturing_ && stamp < after_)) return;  // never asked for
      if (pending_.size() >= kKeptStamps) {
        if (capturing_) return;  // the capture's first stamps stay; later ones are not needed
        pending_.erase(pending_.begin());
      }
      it = pending_.emplace(stamp, StereoMessages{}).first;
    }
    store(it->second);
  }
  arrived_.notify_all();
}

void StereoTopicCamera::onLeft(const sensor_msgs::Image::ConstPtr& m) {
  keep(m->header.stamp, [&](StereoMessages& p) { p.left = m; });
}
void StereoTopicCamera::onRight(const sensor_msgs::Image::ConstPtr& m) {
  keep(m->header.stamp, [&](StereoMessages& p) { p.right = m; });
}
void StereoTopicCamera::onMask(const sensor_msgs::Image::ConstPtr& m) {
  keep(m->header.stamp, [&](StereoMessages& p) { p.mask = m; });
}
void StereoTopicCamera::onDisparity(const stereo_msgs::DisparityImage::ConstPtr& m) {
  keep(m->header.stamp, [&](StereoMessages& p) { p.disparity = m; });
}
void StereoTopicCamera::onLeftInfo(const sensor_msgs::CameraInfo::ConstPtr& m) {
  keep(m->header.stamp, [&](StereoMessages& p) {
    p.left_info = m;
    latest_left_info_ = m;
  });
}
void StereoTopicCamera::onRightInfo(const sensor_msgs::CameraInfo::ConstPtr& m) {
  keep(m->header.stamp, [&](StereoMessages& p) {
    p.right_info = m;
    latest_right_info_ = m;
  });
}

bool StereoTopicCamera::completeAtOrAfter(const ::ros::Time& after, ::ros::Time& stamp) const {
  for (auto it = pending_.lower_bound(after); it != pending_.end(); ++it) {
    if (it->first <= consumed_) continue;  // a pair is captured once
    const StereoMessages& p = it->second;
    // A camera may publish its infos once per stamp or only now and then: the latest serve.
    const bool infos = (p.left_info || latest_left_info_) && (p.right_info || latest_right_info_);
    if (p.left && p.right && infos && (!options_.use_mask || p.mask) &&
        (!options_.use_disparity || p.disparity)) {
      stamp = it->first;
      return true;
    }
  }
  return false;
}

host::nbv::CaptureResult StereoTopicCamera::capture(const Eigen::Isometry3d&) {
  const ::ros::Time after = ::ros::Time::now();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    capturing_ = true;
    after_ = after;
    pending_.erase(pending_.begin(), pending_.lower_bound(after));
  }
  if (trigger_) {
    const auto start = std::chrono::steady_clock::now();
    while (trigger_.getNumSubscribers() == 0 &&
           std::chrono::steady_clock::now() - start <
               std::chrono::duration<double>(options_.timeout_s))
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std_msgs::Header trigger;
    trigger.stamp = after;
    trigger_.publish(trigger);
  }
  host::nbv::CaptureResult out;
  StereoMessages pair;
  ::ros::Time stamp;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    const bool arrived = arrived_.wait_for(lock, std::chrono::duration<double>(options_.timeout_s),
                                           [&] { return completeAtOrAfter(after, stamp); });
    capturing_ = false;
    if (!arrived) {
      out.detail = "no stereo pair on " + options_.topics.left_image + " within " +
                   std::to_string(options_.timeout_s) + " s";
      return out;
    }
    pair = pending_[stamp];
    if (!pair.left_info) pair.left_info = latest_left_info_;
    if (!pair.right_info) pair.right_info = latest_right_info_;
    consumed_ = stamp;
    pending_.erase(pending_.begin(), pending_.upper_bound(stamp));
  }
  std::string why;
  Eigen::Isometry3d T_world_camera;
  if (!poseAt(pair.left->header.frame_id, stamp, T_world_camera, why)) {
    out.detail = why;
    return out;
  }
  try {
    out.frame =
        host::toStereoFrame(captureOfMessages(pair, T_world_camera, options_.topics, source_));
  } catch (const std::runtime_error& e) {  // a driver's malformed pair: dropped, not fatal
    out.detail = e.what();
    return out;
  }
  out.status = host::nbv::CaptureStatus::kOk;
  return out;
}

bool StereoTopicCamera::poseAt(const std::string& frame, const ::ros::Time& stamp,
                               Eigen::Isometry3d& T_world_camera, std::string& why) const {
  // tf2's own timeout runs on ROS time, which stands still when a simulated clock stalls:
  // poll against the wall clock instead.
  const std::string world = frameId(options_.topics.world_frame), camera = frameId(frame);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.tf_timeout_s);
  std::string error;
  while (!tf_.canTransform(world, camera, stamp, &error)) {
    if (std::chrono::steady_clock::now() > deadline) {
      why = "no pose of '" + frame + "' in '" + options_.topics.world_frame + "' at " +
            stampText(stamp) + ": " + error;
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  try {
    T_world_camera = isometryOf(tf_.lookupTransform(world, camera, stamp).transform);
  } catch (const tf2::TransformException& e) {
    why = e.what();
    return false;
  }
  return true;
}

}  // namespace fvp::ros
