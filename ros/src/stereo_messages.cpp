// A stereo pair as ROS 1 messages and back (docs/ros.md). C++17: ROS 1's message headers use
// std::allocator<void>::rebind, which C++20 removed.
#include "fvp/ros/stereo_messages.h"

#include <cv_bridge/cv_bridge.h>

#include <algorithm>
#include <boost/make_shared.hpp>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace fvp::ros {
namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw std::runtime_error(source + ": " + what);
}

sensor_msgs::CameraInfo cameraInfo(const host::StereoIntrinsics& K, const std_msgs::Header& header,
                                   bool right) {
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = K.width_px;
  info.height = K.height_px;
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);  // rectified: no distortion left
  info.K = {K.fx_px, 0.0, K.cx_px, 0.0, K.fy_px, K.cy_px, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {K.fx_px, 0.0,     K.cx_px, right ? -K.fx_px * K.baseline_m : 0.0,
            0.0,     K.fy_px, K.cy_px, 0.0,
            0.0,     0.0,     1.0,     0.0};
  return info;
}

/// The intrinsics of a rectified pair: the left camera's projection, the baseline from the
/// right one's P[3] = -fx * baseline.
host::StereoIntrinsics intrinsicsOf(const sensor_msgs::CameraInfo& left,
                                    const sensor_msgs::CameraInfo& right, const std::string& source,
                                    const StereoBagTopics& topics) {
  const std::string where = topics.left_info + " at " + stampText(left.header.stamp);
  host::StereoIntrinsics K;
  K.width_px = int(left.width);
  K.height_px = int(left.height);
  K.fx_px = left.P[0];
  K.fy_px = left.P[5];
  K.cx_px = left.P[2];
  K.cy_px = left.P[6];
  if (!(K.fx_px > 0.0) || !(K.fy_px > 0.0))
    fail(source, where + ": camera_info P: expected a rectified projection with fx, fy > 0");
  const std::string right_where = topics.right_info + " at " + stampText(right.header.stamp);
  // A rectified pair shares its projection; only the right one's P[3] differs.
  for (const int i : {0, 2, 5, 6})
    if (!(std::abs(right.P[i] - left.P[i]) <= 1e-6 * std::abs(left.P[i]) + 1e-9))
      fail(source,
           right_where + ": P[" + std::to_string(i) +
               "]: expected the left camera_info's (a rectified pair shares fx, fy, cx, cy)");
  K.baseline_m = -right.P[3] / right.P[0];
  if (!(K.baseline_m > 0.0))
    fail(source, right_where + ": P[3]: expected -fx * baseline with a baseline > 0");
  return K;
}

cv::Mat imageOf(const sensor_msgs::Image::ConstPtr& image, const std::string& encoding,
                const std::string& source, const std::string& where) {
  try {
    return encoding.empty() ? cv_bridge::toCvCopy(image)->image
                            : cv_bridge::toCvCopy(image, encoding)->image;
  } catch (const cv_bridge::Exception& e) {
    fail(source, where + ": encoding '" + image->encoding + "': " + e.what());
  }
}

stereo_msgs::DisparityImage disparityMsg(const host::Capture& c, const std_msgs::Header& header) {
  stereo_msgs::DisparityImage d;
  d.header = header;
  d.image = *cv_bridge::CvImage(header, "32FC1", c.disparity_px).toImageMsg();
  d.f = float(c.intrinsics.fx_px);
  d.T = float(c.intrinsics.baseline_m);
  d.min_disparity = 0.0f;  // fvp's convention: 0 (or less) is no disparity
  d.max_disparity = float(c.intrinsics.width_px);
  d.delta_d = float(1.0 / c.disparity_scale);
  return d;
}

/// A stereo_msgs/DisparityImage as a capture's disparity: CV_32F, 0 where invalid (not finite,
/// or not above min_disparity).
cv::Mat disparityOf(const stereo_msgs::DisparityImage& d, const std::string& source,
                    const std::string& where) {
  const auto image = boost::make_shared<sensor_msgs::Image>(d.image);
  cv::Mat disparity = imageOf(image, "32FC1", source, where);
  const float floor = std::max(0.0f, d.min_disparity);
  disparity.forEach<float>([floor](float& v, const int*) {
    if (!std::isfinite(v) || v <= floor) v = 0.0f;
  });
  return disparity;
}

}  // namespace

std::string stampText(const ::ros::Time& t) {
  char text[40];
  std::snprintf(text, sizeof(text), "%u.%03u s", t.sec, t.nsec / 1000000);
  return text;
}

std::string frameId(const std::string& id) {
  return !id.empty() && id[0] == '/' ? id.substr(1) : id;
}

geometry_msgs::TransformStamped transformMsg(const Eigen::Isometry3d& T, const std_msgs::Header& h,
                                             const std::string& child) {
  geometry_msgs::TransformStamped t;
  t.header = h;
  t.child_frame_id = child;
  t.transform.translation.x = T.translation().x();
  t.transform.translation.y = T.translation().y();
  t.transform.translation.z = T.translation().z();
  const Eigen::Quaterniond q(T.linear());
  t.transform.rotation.w = q.w();
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  return t;
}

Eigen::Isometry3d isometryOf(const geometry_msgs::Transform& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
  T.linear() = Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  return T;
}

geometry_msgs::Point pointMsg(const Eigen::Vector3d& p) {
  geometry_msgs::Point out;
  out.x = p.x();
  out.y = p.y();
  out.z = p.z();
  return out;
}

geometry_msgs::Pose poseMsg(const Eigen::Isometry3d& T) {
  geometry_msgs::Pose pose;
  pose.position = pointMsg(T.translation());
  const Eigen::Quaterniond q(T.linear());
  pose.orientation.w = q.w();
  pose.orientation.x = q.x();
  pose.orientation.y = q.y();
  pose.orientation.z = q.z();
  return pose;
}

StereoMessages stereoMessagesOf(const host::Capture& c, const std_msgs::Header& header) {
  StereoMessages m;
  m.left_info =
      boost::make_shared<sensor_msgs::CameraInfo>(cameraInfo(c.intrinsics, header, false));
  m.right_info =
      boost::make_shared<sensor_msgs::CameraInfo>(cameraInfo(c.intrinsics, header, true));
  m.left = cv_bridge::CvImage(header, "bgr8", c.left_bgr).toImageMsg();
  m.right = cv_bridge::CvImage(header, "bgr8", c.right_bgr).toImageMsg();
  if (!c.disparity_px.empty())
    m.disparity = boost::make_shared<stereo_msgs::DisparityImage>(disparityMsg(c, header));
  if (!c.fruitlet_mask.empty())
    m.mask = cv_bridge::CvImage(header, c.fruitlet_mask.depth() == CV_16U ? "mono16" : "mono8",
                                c.fruitlet_mask)
                 .toImageMsg();
  return m;
}

host::Capture captureOfMessages(const StereoMessages& p, const Eigen::Isometry3d& T_world_camera,
                                const StereoBagTopics& topics, const std::string& source) {
  if (!p.left || !p.right || !p.left_info || !p.right_info)
    throw std::invalid_argument("captureOfMessages: a pair needs both images and camera infos");
  const ::ros::Time stamp = p.left->header.stamp;
  const std::string where = topics.left_image + " at " + stampText(stamp);
  host::Capture capture;
  capture.T_world_camera = T_world_camera;
  capture.intrinsics = intrinsicsOf(*p.left_info, *p.right_info, source, topics);
  capture.left_bgr = imageOf(p.left, "bgr8", source, where);
  capture.right_bgr =
      imageOf(p.right, "bgr8", source, topics.right_image + " at " + stampText(stamp));
  const cv::Size size(capture.intrinsics.width_px, capture.intrinsics.height_px);
  for (const cv::Mat* image : {&capture.left_bgr, &capture.right_bgr})
    if (image->size() != size)
      fail(source, where + ": image size: expected the camera_info's " +
                       std::to_string(size.width) + " x " + std::to_string(size.height));
  if (p.mask) {
    const std::string mask_where = topics.fruitlet_mask + " at " + stampText(stamp);
    capture.fruitlet_mask = imageOf(p.mask, "", source, mask_where);
    if (capture.fruitlet_mask.size() != size ||
        (capture.fruitlet_mask.type() != CV_8U && capture.fruitlet_mask.type() != CV_16U))
      fail(source, mask_where + ": expected a mono8 or mono16 image of the left image's size");
  }
  if (p.disparity) {
    const std::string d_where = topics.disparity + " at " + stampText(stamp);
    capture.disparity_px = disparityOf(*p.disparity, source, d_where);
    if (capture.disparity_px.size() != size)
      fail(source, d_where + ": image size: expected the left image's");
  }
  return capture;
}

}  // namespace fvp::ros
