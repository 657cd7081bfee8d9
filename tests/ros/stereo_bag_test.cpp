// Stereo bags <-> captures (ros/include/fvp/ros/stereo_bag.h): every part of a capture comes
// back as it went in, what cannot be used is counted, bad input names the bag, topic and field.
#include "fvp/ros/stereo_bag.h"

#include "fvp/ros/bag_structure.h"

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>
#include <visualization_msgs/MarkerArray.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace fvp::ros {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("fvp_stereo_bag_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

host::Capture capture(int i) {
  host::Capture c;
  c.intrinsics.width_px = 64;
  c.intrinsics.height_px = 48;
  c.intrinsics.fx_px = 100.5;
  c.intrinsics.fy_px = 101.0;
  c.intrinsics.cx_px = 31.5;
  c.intrinsics.cy_px = 23.25;
  c.intrinsics.baseline_m = 0.06;
  c.left_bgr = cv::Mat(48, 64, CV_8UC3);
  c.right_bgr = cv::Mat(48, 64, CV_8UC3);
  c.fruitlet_mask = cv::Mat(48, 64, CV_16U);
  c.disparity_px = cv::Mat(48, 64, CV_32F);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      c.left_bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 4, y * 5, (x + y + i) % 256);
      c.right_bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(y * 5, x * 4, (x * y + i) % 256);
      c.fruitlet_mask.at<std::uint16_t>(y, x) = std::uint16_t(x > 30 ? 300 + i : 0);
      c.disparity_px.at<float>(y, x) = (x + y) % 7 == 0 ? 0.0f : float(x % 40) / 16.0f + 1.0f;
    }
  c.T_world_camera = Eigen::Translation3d(0.1 * i, -0.2, 1.0) *
                     Eigen::AngleAxisd(0.3 + 0.4 * i, Eigen::Vector3d(1, 2, 3).normalized());
  return c;
}

double difference(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return 1e9;
  return cv::norm(a, b, cv::NORM_INF);
}

TEST(StereoBag, EveryPartOfACaptureComesBackAsItWentIn) {
  const std::vector<host::Capture> written = {capture(0), capture(1), capture(2)};
  const fs::path bag = scratch("round_trip.bag");
  writeStereoBag(bag, written, StereoBagTopics{});
  std::vector<host::Capture> read;
  const StereoBagStats stats =
      readStereoBag(bag, StereoBagTopics{}, [&](host::Capture&& c) { read.push_back(c); });
  EXPECT_EQ(stats.pairs, 3u);
  EXPECT_EQ(stats.with_mask, 3u);
  EXPECT_EQ(stats.with_disparity, 3u);
  EXPECT_EQ(stats.unpaired_images + stats.without_pose + stats.without_info, 0u);
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    const host::Capture& a = written[i];
    const host::Capture& b = read[i];
    EXPECT_EQ(difference(a.left_bgr, b.left_bgr), 0.0) << i;
    EXPECT_EQ(difference(a.right_bgr, b.right_bgr), 0.0) << i;
    EXPECT_EQ(difference(a.fruitlet_mask, b.fruitlet_mask), 0.0) << i;
    EXPECT_EQ(difference(a.disparity_px, b.disparity_px), 0.0) << i;
    EXPECT_EQ(b.intrinsics.width_px, 64);
    EXPECT_EQ(b.intrinsics.height_px, 48);
    EXPECT_DOUBLE_EQ(b.intrinsics.fx_px, a.intrinsics.fx_px);
    EXPECT_DOUBLE_EQ(b.intrinsics.fy_px, a.intrinsics.fy_px);
    EXPECT_DOUBLE_EQ(b.intrinsics.cx_px, a.intrinsics.cx_px);
    EXPECT_DOUBLE_EQ(b.intrinsics.cy_px, a.intrinsics.cy_px);
    EXPECT_NEAR(b.intrinsics.baseline_m, a.intrinsics.baseline_m, 1e-15);
    EXPECT_LT((b.T_world_camera.matrix() - a.T_world_camera.matrix()).cwiseAbs().maxCoeff(), 1e-12)
        << i;
  }
  fs::remove(bag);
}

TEST(StereoBag, ARecordingCarriesItsViewsAndDetectionsForRViz) {
  const fs::path bag = scratch("markers.bag");
  {
    StereoBagWriter writer(bag, StereoBagTopics{});
    writer.add(capture(0), 1.0);
    writer.add(capture(1), 2.0);
    writer.addMarkers({{Eigen::Vector3d(0.1, 0.2, 1.0), 12.5, true},
                       {Eigen::Vector3d(0.1, 0.3, 1.0), 7.0, false}},
                      3.0);
    writer.close();
  }
  rosbag::Bag reader(bag.string(), rosbag::bagmode::Read);
  rosbag::View view(reader, rosbag::TopicQuery(std::vector<std::string>{kBagMarkersTopic}));
  ASSERT_EQ(view.size(), 1u);
  const auto markers = view.begin()->instantiate<visualization_msgs::MarkerArray>();
  ASSERT_TRUE(markers);
  std::map<std::string, int> per_namespace;
  for (const auto& m : markers->markers) {
    ++per_namespace[m.ns];
    EXPECT_EQ(m.header.frame_id, "world");
    if (m.ns == "fruitlets") {
      EXPECT_DOUBLE_EQ(m.scale.x, 0.0125);  // its diameter
    }
    if (m.ns == "fruitlet_sizes") {
      EXPECT_EQ(m.text, "12.5 mm");
    }
  }
  EXPECT_EQ(per_namespace["views"], 2);
  EXPECT_EQ(per_namespace["camera_path"], 1);
  EXPECT_EQ(per_namespace["fruitlets"], 1);
  EXPECT_EQ(per_namespace["dropped_detections"], 1);
  EXPECT_EQ(per_namespace["dropped_sizes"], 1);
  reader.close();
  // The stereo reader takes the pairs as before.
  EXPECT_EQ(readStereoBag(bag, StereoBagTopics{}, [](host::Capture&&) {}).pairs, 2u);
  fs::remove(bag);
}

sensor_msgs::Image image(const ::ros::Time& stamp, int width) {
  sensor_msgs::Image m;
  m.header.stamp = stamp;
  m.header.frame_id = "cam";
  m.encoding = "mono8";
  m.width = std::uint32_t(width);
  m.height = 4;
  m.step = std::uint32_t(width);
  m.data.assign(std::size_t(width) * 4, 128);
  return m;
}

sensor_msgs::CameraInfo info(const ::ros::Time& stamp, bool right) {
  sensor_msgs::CameraInfo m;
  m.header.stamp = stamp;
  m.header.frame_id = "cam";
  m.width = 8;
  m.height = 4;
  m.P = {50.0, 0.0, 4.0, right ? -50.0 * 0.1 : 0.0, 0.0, 50.0, 2.0, 0.0, 0.0, 0.0, 1.0, 0.0};
  return m;
}

tf2_msgs::TFMessage pose(const ::ros::Time& stamp) {
  tf2_msgs::TFMessage m;
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = "world";
  t.child_frame_id = "cam";
  t.transform.rotation.w = 1.0;
  m.transforms.push_back(t);
  return m;
}

/// Writes a bag by hand: pair(stamp) writes a left and right image of that stamp.
struct HandBag {
  explicit HandBag(const fs::path& path) : bag(path.string(), rosbag::bagmode::Write) {}
  void pair(double s, int left_width = 8) {
    const ::ros::Time t(s);
    bag.write(topics.left_image, t, image(t, left_width));
    bag.write(topics.right_image, t, image(t, 8));
  }
  void infos(double s) {
    const ::ros::Time t(s);
    bag.write(topics.left_info, t, info(t, false));
    bag.write(topics.right_info, t, info(t, true));
  }
  StereoBagTopics topics;
  rosbag::Bag bag;
};

StereoBagStats readAll(const fs::path& path, std::size_t* captures = nullptr) {
  std::size_t n = 0;
  const StereoBagStats stats =
      readStereoBag(path, StereoBagTopics{}, [&](host::Capture&&) { ++n; });
  if (captures) *captures = n;
  return stats;
}

TEST(StereoBag, CountsImagesWithoutAPartnerAPoseOrACameraInfo) {
  const fs::path path = scratch("events.bag");
  {
    HandBag b(path);
    b.bag.write("/tf", ::ros::Time(1.0), pose(::ros::Time(1.0)));
    b.infos(1.0);
    b.pair(1.0);                                                                     // used
    b.bag.write(b.topics.left_image, ::ros::Time(3.0), image(::ros::Time(3.0), 8));  // no right
    b.pair(10.0);  // tf knows the camera at 1 s only: no pose at 10 s
  }
  std::size_t captures = 0;
  const StereoBagStats stats = readAll(path, &captures);
  EXPECT_EQ(stats.pairs, 1u);
  EXPECT_EQ(captures, 1u);
  EXPECT_EQ(stats.unpaired_images, 1u);
  EXPECT_EQ(stats.without_pose, 1u);
  EXPECT_EQ(stats.without_info, 0u);

  const fs::path no_info = scratch("no_info.bag");
  {
    HandBag b(no_info);
    b.bag.write("/tf", ::ros::Time(1.0), pose(::ros::Time(1.0)));
    b.pair(1.0);
  }
  EXPECT_EQ(readAll(no_info).without_info, 1u);
  fs::remove(path);
  fs::remove(no_info);
}

// A camera's stamps need not be the recorder's clock: here every message is recorded 5 s after
// its stamp (the right image 0.3 s after the left), far beyond the 1 s gather window; pairs
// are gathered by stamp. The frames are named in ROS 1's old style, with a leading '/', which
// tf2 does not look up as given.
TEST(StereoBag, PairsByStampWhateverTheRecordTimeAndFrameIdStyle) {
  const fs::path path = scratch("clock.bag");
  {
    HandBag b(path);
    for (const double s : {1.0, 2.0, 3.0}) {
      const ::ros::Time t(s);
      tf2_msgs::TFMessage tf = pose(t);
      tf.transforms[0].child_frame_id = "/cam";
      const ::ros::Time recorded = t + ::ros::Duration(5.0);
      b.bag.write("/tf", recorded, tf);
      b.bag.write(b.topics.left_info, recorded, info(t, false));
      b.bag.write(b.topics.right_info, recorded, info(t, true));
      sensor_msgs::Image left = image(t, 8), right = image(t, 8);
      left.header.frame_id = right.header.frame_id = "/cam";
      b.bag.write(b.topics.left_image, recorded, left);
      b.bag.write(b.topics.right_image, recorded + ::ros::Duration(0.3), right);
    }
  }
  StereoBagTopics topics;
  topics.world_frame = "/world";
  std::size_t captures = 0;
  const StereoBagStats stats = readStereoBag(path, topics, [&](host::Capture&&) { ++captures; });
  EXPECT_EQ(stats.pairs, 3u);
  EXPECT_EQ(captures, 3u);
  EXPECT_EQ(stats.unpaired_images + stats.without_pose + stats.without_info, 0u);
  fs::remove(path);
}

std::string errorOf(const fs::path& path) {
  try {
    readAll(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(StereoBag, BadInputNamesTheBagTheTopicAndTheField) {
  const fs::path wrong_size = scratch("wrong_size.bag");
  {
    HandBag b(wrong_size);
    b.bag.write("/tf", ::ros::Time(1.0), pose(::ros::Time(1.0)));
    b.infos(1.0);
    b.pair(1.0, 10);  // 10 px wide, the camera info says 8
  }
  const std::string size_error = errorOf(wrong_size);
  EXPECT_NE(size_error.find(wrong_size.string()), std::string::npos) << size_error;
  EXPECT_NE(size_error.find("/stereo/left/image_rect_color"), std::string::npos) << size_error;
  EXPECT_NE(size_error.find("image size"), std::string::npos) << size_error;

  const fs::path no_right = scratch("no_right.bag");
  {
    HandBag b(no_right);
    b.bag.write(b.topics.left_image, ::ros::Time(1.0), image(::ros::Time(1.0), 8));
  }
  EXPECT_NE(errorOf(no_right).find("/stereo/right/image_rect_color: expected images"),
            std::string::npos);

  const fs::path not_a_bag = scratch("not_a.bag");
  std::ofstream(not_a_bag) << "#ROSBAG V2.0 but nothing after\n";
  EXPECT_NE(errorOf(not_a_bag).find("not a readable ROS bag"), std::string::npos);
  for (const fs::path& p : {wrong_size, no_right, not_a_bag}) fs::remove(p);
}

std::string bytesOf(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

std::string structureError(const fs::path& p) {
  try {
    checkBagStructure(p);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// rosbag trusts the lengths a file states (a 4 GB header length made it allocate 4 GB: the
// fuzz regression connection_header_len_4GB_oom); the walk refuses them first.
TEST(BagStructure, RefusesLengthsThatLeaveTheFile) {
  const fs::path good = scratch("structure.bag");
  writeStereoBag(good, {capture(0)}, StereoBagTopics{});
  EXPECT_EQ(structureError(good), "");
  const std::string bytes = bytesOf(good);

  const fs::path bad = scratch("structure_bad.bag");
  std::string huge = bytes;
  const std::size_t first_record = 13;  // after "#ROSBAG V2.0\n": the bag header's header_len
  for (int i = 0; i < 4; ++i) huge[first_record + std::size_t(i)] = char(0xff);
  writeBytes(bad, huge);
  const std::string error = structureError(bad);
  EXPECT_NE(error.find(bad.string()), std::string::npos) << error;
  EXPECT_NE(error.find("at byte 13, header_len 4294967295"), std::string::npos) << error;

  writeBytes(bad, bytes.substr(0, bytes.size() - 100));
  EXPECT_NE(structureError(bad).find("not a readable ROS bag"), std::string::npos);
  writeBytes(bad, "#ROSBAG V1.2\n" + bytes.substr(13));
  EXPECT_NE(structureError(bad).find("#ROSBAG V2.0"), std::string::npos);
  // readStereoBag checks first: the same error, not rosbag's allocation.
  writeBytes(bad, huge);
  EXPECT_NE(errorOf(bad).find("header_len"), std::string::npos);
  fs::remove(good);
  fs::remove(bad);
}

}  // namespace
}  // namespace fvp::ros
