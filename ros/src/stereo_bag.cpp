// Stereo bags <-> captures (docs/ros.md). C++17: ROS 1's message headers use
// std::allocator<void>::rebind, which C++20 removed.
#include "fvp/ros/stereo_bag.h"

#include "fvp/ros/bag_structure.h"
#include "fvp/ros/rviz_markers.h"
#include "fvp/ros/stereo_messages.h"

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

/// The message, when it is of type T and its serialized bytes hold what they state
/// (serializedMessageFits: roscpp allocates by stated lengths); else null for another type, and
/// an error naming the bag and topic for bytes that do not hold together.
template <typename T>
boost::shared_ptr<T> checkedMessage(const rosbag::MessageInstance& m, BagMessage type,
                                    const std::filesystem::path& bag) {
  if (!m.isType<T>()) return nullptr;
  std::vector<std::uint8_t> bytes(m.size());
  ::ros::serialization::OStream out(bytes.data(), std::uint32_t(bytes.size()));
  m.write(out);
  if (!serializedMessageFits(type, bytes.data(), bytes.size()))
    fail(bag, m.getTopic() + " at " + stampText(m.getTime()) + ": expected a whole " +
                  m.getDataType() + " (a length inside it runs past its end)");
  // From the checked bytes: the bag is read once per message.
  auto message = boost::make_shared<T>();
  ::ros::serialization::IStream in(bytes.data(), std::uint32_t(bytes.size()));
  ::ros::serialization::deserialize(in, *message);
  return message;
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
  const StereoMessages m = stereoMessagesOf(c, header);
  rosbag::Bag& bag = bag_->bag;
  try {
    bag.write("/tf", header.stamp, tf);
    bag.write(topics_.left_info, header.stamp, m.left_info);
    bag.write(topics_.right_info, header.stamp, m.right_info);
    bag.write(topics_.left_image, header.stamp, m.left);
    bag.write(topics_.right_image, header.stamp, m.right);
    if (m.disparity) bag.write(topics_.disparity, header.stamp, m.disparity);
    if (m.mask) bag.write(topics_.fruitlet_mask, header.stamp, m.mask);
  } catch (const ::ros::Exception& e) {
    fail(bag_->path, std::string("cannot be written: ") + e.what());
  }
  ++pairs_;
  camera_poses_.push_back(c.T_world_camera);
}

void StereoBagWriter::addMarkers(const std::vector<BagDetection>& detections, double stamp_s) {
  if (!bag_) throw std::logic_error("StereoBagWriter::addMarkers after close");
  const std::string& frame = topics_.world_frame;
  visualization_msgs::MarkerArray markers;
  std::vector<Eigen::Vector3d> path_m;
  for (std::size_t i = 0; i < camera_poses_.size(); ++i) {
    path_m.push_back(camera_poses_[i].translation());
    markers.markers.push_back(viewMarker(camera_poses_[i], frame, int(i)));
  }
  markers.markers.push_back(cameraPathMarker(path_m, frame));
  for (std::size_t i = 0; i < detections.size(); ++i)
    addFruitletMarkers(markers, detections[i].center_m, detections[i].size_mm, detections[i].kept,
                       frame, int(i));
  try {
    bag_->bag.write(kBagMarkersTopic, ::ros::Time(stamp_s), markers);
  } catch (const ::ros::Exception& e) {
    fail(bag_->path, std::string("cannot be written: ") + e.what());
  }
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
      StereoMessages& parts = pending_[info->header.stamp];
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
      StereoMessages& parts = pending_[image->header.stamp];
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
  std::optional<host::Capture> captureOf(const ::ros::Time& stamp, StereoMessages p) {
    if (!p.left_info) p.left_info = latest_left_info_;
    if (!p.right_info) p.right_info = latest_right_info_;
    if (!p.left_info || !p.right_info) {
      ++stats_.without_info;
      return std::nullopt;
    }
    Eigen::Isometry3d T_world_camera;
    try {
      T_world_camera = isometryOf(
          tf_.lookupTransform(frameId(topics_.world_frame), frameId(p.left->header.frame_id), stamp)
              .transform);
    } catch (const tf2::TransformException&) {
      ++stats_.without_pose;
      return std::nullopt;
    }
    host::Capture capture = captureOfMessages(p, T_world_camera, topics_, bag_.string());
    if (!capture.fruitlet_mask.empty()) ++stats_.with_mask;
    if (!capture.disparity_px.empty()) ++stats_.with_disparity;
    ++stats_.pairs;
    return capture;
  }

  const std::filesystem::path& bag_;
  const StereoBagTopics& topics_;
  const tf2::BufferCore& tf_;
  StereoBagStats& stats_;
  std::map<::ros::Time, StereoMessages> pending_;
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
