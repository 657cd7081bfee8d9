// Stereo bags <-> captures (docs/ros.md). C++17: ROS 1's message headers use
// std::allocator<void>::rebind, which C++20 removed.
#include "fvp/ros/stereo_bag.h"

#include "fvp/ros/bag_structure.h"

#include <cv_bridge/cv_bridge.h>
#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <stereo_msgs/DisparityImage.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_msgs/TFMessage.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <boost/make_shared.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

namespace fvp::ros {
namespace {

using ImagePtr = sensor_msgs::Image::ConstPtr;

[[noreturn]] void fail(const std::filesystem::path& bag, const std::string& what) {
  throw std::runtime_error(bag.string() + ": " + what);
}

std::string stampText(const ::ros::Time& t) {
  char text[40];
  std::snprintf(text, sizeof(text), "%u.%03u s", t.sec, t.nsec / 1000000);
  return text;
}

/// tf2 keeps frame ids without a leading '/' (ROS 1's old style) and refuses to look one up.
std::string frameId(const std::string& id) {
  return !id.empty() && id[0] == '/' ? id.substr(1) : id;
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

/// The message, when it is of type T and its serialized bytes hold what they state
/// (serializedMessageFits: roscpp allocates by stated lengths); else null for another type, and
/// an error naming the bag and topic for bytes that do not hold together.
template <typename T>
boost::shared_ptr<T> checkedMessage(const rosbag::MessageInstance& m, BagMessage type,
                                    const std::filesystem::path& bag) {
  if (!m.isType<T>()) return nullptr;
  std::vector<std::uint8_t> bytes(m.size());
  ::ros::serialization::OStream stream(bytes.data(), std::uint32_t(bytes.size()));
  m.write(stream);
  if (!serializedMessageFits(type, bytes.data(), bytes.size()))
    fail(bag, m.getTopic() + " at " + stampText(m.getTime()) + ": expected a whole " +
                  m.getDataType() + " (a length inside it runs past its end)");
  return m.instantiate<T>();
}

/// Every transform of the bag's /tf and /tf_static, kept for the whole bag.
std::unique_ptr<tf2::BufferCore> bagTransforms(rosbag::Bag& bag,
                                               const std::filesystem::path& path) {
  rosbag::View all(bag);
  const double span_s = all.size() == 0 ? 0.0 : (all.getEndTime() - all.getBeginTime()).toSec();
  auto buffer = std::make_unique<tf2::BufferCore>(::ros::Duration(span_s + 10.0));
  rosbag::View tf(bag, rosbag::TopicQuery(std::vector<std::string>{"/tf", "/tf_static"}));
  for (const rosbag::MessageInstance& m : tf) {
    const auto message = checkedMessage<tf2_msgs::TFMessage>(m, BagMessage::kTf, path);
    if (!message) continue;
    const bool is_static = m.getTopic() == "/tf_static";
    for (const geometry_msgs::TransformStamped& t : message->transforms)
      buffer->setTransform(t, "bag", is_static);
  }
  return buffer;
}

/// The intrinsics of a rectified pair: the left camera's projection, the baseline from the
/// right one's P[3] = -fx * baseline.
host::StereoIntrinsics intrinsicsOf(const sensor_msgs::CameraInfo& left,
                                    const sensor_msgs::CameraInfo& right,
                                    const std::filesystem::path& bag,
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
    fail(bag, where + ": camera_info P: expected a rectified projection with fx, fy > 0");
  const std::string right_where = topics.right_info + " at " + stampText(right.header.stamp);
  // A rectified pair shares its projection; only the right one's P[3] differs.
  for (const int i : {0, 2, 5, 6})
    if (!(std::abs(right.P[i] - left.P[i]) <= 1e-6 * std::abs(left.P[i]) + 1e-9))
      fail(bag, right_where + ": P[" + std::to_string(i) +
                    "]: expected the left camera_info's (a rectified pair shares fx, fy, cx, cy)");
  K.baseline_m = -right.P[3] / right.P[0];
  if (!(K.baseline_m > 0.0))
    fail(bag, right_where + ": P[3]: expected -fx * baseline with a baseline > 0");
  return K;
}

cv::Mat imageOf(const ImagePtr& image, const std::string& encoding,
                const std::filesystem::path& bag, const std::string& where) {
  try {
    return encoding.empty() ? cv_bridge::toCvCopy(image)->image
                            : cv_bridge::toCvCopy(image, encoding)->image;
  } catch (const cv_bridge::Exception& e) {
    fail(bag, where + ": encoding '" + image->encoding + "': " + e.what());
  }
}

/// One stamp's messages, gathered as they come.
struct Parts {
  ImagePtr left, right, mask;
  stereo_msgs::DisparityImage::ConstPtr disparity;
  sensor_msgs::CameraInfo::ConstPtr left_info, right_info;
};

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
cv::Mat disparityOf(const stereo_msgs::DisparityImage& d, const std::filesystem::path& bag,
                    const std::string& where) {
  const auto image = boost::make_shared<sensor_msgs::Image>(d.image);
  cv::Mat disparity = imageOf(image, "32FC1", bag, where);
  const float floor = std::max(0.0f, d.min_disparity);
  disparity.forEach<float>([floor](float& v, const int*) {
    if (!std::isfinite(v) || v <= floor) v = 0.0f;
  });
  return disparity;
}

}  // namespace

struct StereoBagWriter::Bag {
  std::filesystem::path path;
  rosbag::Bag bag;
};

StereoBagWriter::StereoBagWriter(const std::filesystem::path& bag, StereoBagTopics topics,
                                 std::string camera_frame)
    : bag_(std::make_unique<Bag>()),
      topics_(std::move(topics)),
      camera_frame_(std::move(camera_frame)) {
  bag_->path = bag;
  try {
    bag_->bag.open(bag.string(), rosbag::bagmode::Write);
  } catch (const ::ros::Exception& e) {
    fail(bag, std::string("cannot be written: ") + e.what());
  }
}

StereoBagWriter::~StereoBagWriter() {
  try {
    close();
  } catch (const std::exception&) {
    // A destructor must not throw; close() explicitly to hear of it.
  }
}

void StereoBagWriter::close() {
  if (bag_) bag_->bag.close();
  bag_.reset();
}

void StereoBagWriter::add(const host::Capture& c, double stamp_s) {
  if (!bag_) throw std::logic_error("StereoBagWriter::add after close");
  std_msgs::Header header;
  header.stamp = ::ros::Time(stamp_s);
  header.frame_id = camera_frame_;
  header.seq = std::uint32_t(pairs_);
  std_msgs::Header world = header;
  world.frame_id = topics_.world_frame;
  tf2_msgs::TFMessage tf;
  tf.transforms.push_back(transformMsg(c.T_world_camera, world, camera_frame_));
  rosbag::Bag& bag = bag_->bag;
  try {
    bag.write("/tf", header.stamp, tf);
    bag.write(topics_.left_info, header.stamp, cameraInfo(c.intrinsics, header, false));
    bag.write(topics_.right_info, header.stamp, cameraInfo(c.intrinsics, header, true));
    bag.write(topics_.left_image, header.stamp,
              cv_bridge::CvImage(header, "bgr8", c.left_bgr).toImageMsg());
    bag.write(topics_.right_image, header.stamp,
              cv_bridge::CvImage(header, "bgr8", c.right_bgr).toImageMsg());
    if (!c.disparity_px.empty())
      bag.write(topics_.disparity, header.stamp, disparityMsg(c, header));
    if (!c.fruitlet_mask.empty())
      bag.write(topics_.fruitlet_mask, header.stamp,
                cv_bridge::CvImage(header, c.fruitlet_mask.depth() == CV_16U ? "mono16" : "mono8",
                                   c.fruitlet_mask)
                    .toImageMsg());
  } catch (const ::ros::Exception& e) {
    fail(bag_->path, std::string("cannot be written: ") + e.what());
  }
  ++pairs_;
}

void writeStereoBag(const std::filesystem::path& bag_path,
                    const std::vector<host::Capture>& captures, const StereoBagTopics& topics,
                    const std::string& camera_frame, double start_s, double period_s) {
  StereoBagWriter writer(bag_path, topics, camera_frame);
  for (std::size_t i = 0; i < captures.size(); ++i)
    writer.add(captures[i], start_s + double(i) * period_s);
  writer.close();
}

namespace {

/// The capture of one stamp's messages, or why there is none (counted in stats).
class PairReader {
 public:
  PairReader(const std::filesystem::path& bag, const StereoBagTopics& topics,
             const tf2::BufferCore& tf, StereoBagStats& stats)
      : bag_(bag), topics_(topics), tf_(tf), stats_(stats) {}

  void add(const rosbag::MessageInstance& m) {
    const std::string& topic = m.getTopic();
    if (topic == topics_.left_info || topic == topics_.right_info) {
      const auto info = checkedMessage<sensor_msgs::CameraInfo>(m, BagMessage::kCameraInfo, bag_);
      if (!info) fail(bag_, topic + ": expected sensor_msgs/CameraInfo");
      Parts& parts = pending_[info->header.stamp];
      (topic == topics_.left_info ? parts.left_info : parts.right_info) = info;
      (topic == topics_.left_info ? latest_left_info_ : latest_right_info_) = info;
    } else if (topic == topics_.disparity) {
      const auto d =
          checkedMessage<stereo_msgs::DisparityImage>(m, BagMessage::kDisparityImage, bag_);
      if (!d) fail(bag_, topic + ": expected stereo_msgs/DisparityImage");
      pending_[d->header.stamp].disparity = d;
    } else {
      const ImagePtr image = checkedMessage<sensor_msgs::Image>(m, BagMessage::kImage, bag_);
      if (!image) fail(bag_, topic + ": expected sensor_msgs/Image");
      newest_image_ = std::max(newest_image_, image->header.stamp);
      Parts& parts = pending_[image->header.stamp];
      (topic == topics_.left_image    ? parts.left
       : topic == topics_.right_image ? parts.right
                                      : parts.mask) = image;
    }
  }

  /// The newest image stamp seen so far.
  ::ros::Time newestImage() const { return newest_image_; }

  /// Gives every gathered stamp older than `before` (all of them by default) to `each`.
  void flush(const std::function<void(host::Capture&&)>& each,
             ::ros::Time before = ::ros::TIME_MAX) {
    while (!pending_.empty() && pending_.begin()->first < before) {
      const auto& [stamp, parts] = *pending_.begin();
      if (parts.left && parts.right) {
        if (std::optional<host::Capture> capture = captureOf(stamp, parts))
          each(std::move(*capture));
      } else if (parts.left || parts.right) {
        ++stats_.unpaired_images;
      }
      pending_.erase(pending_.begin());
    }
  }

 private:
  std::optional<host::Capture> captureOf(const ::ros::Time& stamp, const Parts& p) {
    const std::string where = topics_.left_image + " at " + stampText(stamp);
    const auto left_info = p.left_info ? p.left_info : latest_left_info_;
    const auto right_info = p.right_info ? p.right_info : latest_right_info_;
    if (!left_info || !right_info) {
      ++stats_.without_info;
      return std::nullopt;
    }
    host::Capture capture;
    try {
      capture.T_world_camera = isometryOf(
          tf_.lookupTransform(frameId(topics_.world_frame), frameId(p.left->header.frame_id), stamp)
              .transform);
    } catch (const tf2::TransformException&) {
      ++stats_.without_pose;
      return std::nullopt;
    }
    capture.intrinsics = intrinsicsOf(*left_info, *right_info, bag_, topics_);
    capture.left_bgr = imageOf(p.left, "bgr8", bag_, where);
    capture.right_bgr =
        imageOf(p.right, "bgr8", bag_, topics_.right_image + " at " + stampText(stamp));
    const cv::Size size(capture.intrinsics.width_px, capture.intrinsics.height_px);
    for (const cv::Mat* image : {&capture.left_bgr, &capture.right_bgr})
      if (image->size() != size)
        fail(bag_, where + ": image size: expected the camera_info's " +
                       std::to_string(size.width) + " x " + std::to_string(size.height));
    if (p.mask) {
      const std::string mask_where = topics_.fruitlet_mask + " at " + stampText(stamp);
      capture.fruitlet_mask = imageOf(p.mask, "", bag_, mask_where);
      if (capture.fruitlet_mask.size() != size ||
          (capture.fruitlet_mask.type() != CV_8U && capture.fruitlet_mask.type() != CV_16U))
        fail(bag_, mask_where + ": expected a mono8 or mono16 image of the left image's size");
      ++stats_.with_mask;
    }
    if (p.disparity) {
      const std::string d_where = topics_.disparity + " at " + stampText(stamp);
      capture.disparity_px = disparityOf(*p.disparity, bag_, d_where);
      if (capture.disparity_px.size() != size)
        fail(bag_, d_where + ": image size: expected the left image's");
      ++stats_.with_disparity;
    }
    ++stats_.pairs;
    return capture;
  }

  const std::filesystem::path& bag_;
  const StereoBagTopics& topics_;
  const tf2::BufferCore& tf_;
  StereoBagStats& stats_;
  std::map<::ros::Time, Parts> pending_;
  sensor_msgs::CameraInfo::ConstPtr latest_left_info_, latest_right_info_;
  ::ros::Time newest_image_;
};

StereoBagStats readCheckedBag(const std::filesystem::path& bag_path, const StereoBagTopics& topics,
                              const std::function<void(host::Capture&&)>& each) {
  rosbag::Bag bag;
  bag.open(bag_path.string(), rosbag::bagmode::Read);
  const std::unique_ptr<tf2::BufferCore> tf = bagTransforms(bag, bag_path);
  const std::vector<std::string> wanted = {topics.left_image,    topics.right_image,
                                           topics.left_info,     topics.right_info,
                                           topics.fruitlet_mask, topics.disparity};
  rosbag::View view(bag, rosbag::TopicQuery(wanted));
  std::set<std::string> present;
  for (const rosbag::ConnectionInfo* c : view.getConnections()) present.insert(c->topic);
  for (const std::string& topic : {topics.left_image, topics.right_image})
    if (!present.count(topic))
      fail(bag_path, topic + ": expected images on this topic, found none");
  StereoBagStats stats;
  PairReader reader(bag_path, topics, *tf, stats);
  const ::ros::Duration window(kGatherWindowS);
  for (const rosbag::MessageInstance& m : view) {
    reader.add(m);
    // Stamps, not record times: a camera's clock may run apart from the recorder's.
    if (reader.newestImage() > ::ros::Time(0) + window)
      reader.flush(each, reader.newestImage() - window);
  }
  reader.flush(each);
  return stats;
}

}  // namespace

StereoBagStats readStereoBag(const std::filesystem::path& bag_path, const StereoBagTopics& topics,
                             const std::function<void(host::Capture&&)>& each) {
  checkBagStructure(bag_path);  // rosbag trusts the lengths a file states
  try {
    return readCheckedBag(bag_path, topics, each);
  } catch (const ::ros::Exception& e) {  // rosbag's, rostime's: their messages name no file
    fail(bag_path, std::string("not a readable ROS bag: ") + e.what());
  }
}

}  // namespace fvp::ros
