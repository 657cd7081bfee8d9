// Stereo bags and capture sets (docs/ros.md): a ROS 1 bag of rectified stereo pairs with their
// camera infos and tf, read as fvp's captures (docs/capture-format.md), and captures written as
// such a bag. This header is C++17, as ROS 1's message headers are.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fvp/host/perception/capture.h"

namespace fvp::ros {

/// Where a stereo pair lives in a bag. The defaults are stereo_image_proc's names under
/// /stereo; the camera's frame is the left image's header.frame_id.
struct StereoBagTopics {
  std::string left_image = "/stereo/left/image_rect_color";
  std::string right_image = "/stereo/right/image_rect_color";
  std::string left_info = "/stereo/left/camera_info";
  std::string right_info = "/stereo/right/camera_info";
  /// Optional: the robot's own segmentation of the left image, with its stamp (mono8: nonzero =
  /// fruitlet; mono16: instance ids), used as a capture's mask.png is.
  std::string fruitlet_mask = "/stereo/left/fruitlet_mask";
  /// Optional: the robot's own disparity of the left image (stereo_msgs/DisparityImage), used
  /// as a capture's disparity.png is (SGBM runs only where there is none).
  std::string disparity = "/stereo/disparity";
  std::string world_frame = "world";

  /// The same names under another stereo namespace (e.g. "/camera"), in another world frame.
  static StereoBagTopics under(const std::string& ns, const std::string& world_frame) {
    StereoBagTopics t;
    for (std::string* topic : {&t.left_image, &t.right_image, &t.left_info, &t.right_info,
                               &t.fruitlet_mask, &t.disparity})
      *topic = ns + topic->substr(std::string("/stereo").size());
    t.world_frame = world_frame;
    return t;
  }
};

/// What a bag held, and what of it could not be used: expected events, counted, never errors.
struct StereoBagStats {
  std::size_t pairs = 0;            ///< stereo pairs given as captures
  std::size_t with_mask = 0;        ///< of those, with the fruitlet mask
  std::size_t with_disparity = 0;   ///< of those, with the disparity
  std::size_t unpaired_images = 0;  ///< a left or right image with no partner of its stamp
  std::size_t without_pose = 0;     ///< pairs tf could not place in world_frame at their stamp
  std::size_t without_info = 0;     ///< pairs with no camera info of either side yet
};

/// A detection drawn in a recording (StereoBagWriter::addMarkers).
struct BagDetection {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  double size_mm = 0.0;
  bool kept = true;  ///< false: a detection the support rule dropped
};

/// Where a recording's RViz markers go: the fvp node's own marker topic.
inline constexpr const char* kBagMarkersTopic = "/fvp/markers";

/// A stereo bag written a pair at a time (writeStereoBag, fvp run --bag): each add() writes the
/// pair, its camera infos, the pose on /tf and the mask and disparity when present, stamped
/// stamp_s. close() finishes the bag (the destructor closes it too).
class StereoBagWriter {
 public:
  StereoBagWriter(const std::filesystem::path& bag, StereoBagTopics topics,
                  std::string camera_frame = "stereo_left_optical");
  ~StereoBagWriter();
  StereoBagWriter(const StereoBagWriter&) = delete;
  StereoBagWriter& operator=(const StereoBagWriter&) = delete;
  void add(const host::Capture& capture, double stamp_s);
  /// Writes on kBagMarkersTopic, stamped stamp_s, what RViz shows of the recording
  /// (visualization_msgs/MarkerArray, docs/ros.md "RViz"): the camera path and a view arrow per
  /// pair added so far, and the detections as spheres with their sizes.
  void addMarkers(const std::vector<BagDetection>& detections, double stamp_s);
  void close();
  std::size_t pairs() const { return pairs_; }

 private:
  struct Bag;
  std::unique_ptr<Bag> bag_;
  StereoBagTopics topics_;
  std::string camera_frame_;
  std::size_t pairs_ = 0;
  std::vector<Eigen::Isometry3d> camera_poses_;  ///< of the pairs added, for addMarkers
};

/// Writes each capture as one stereo pair stamped start_s + i * period_s: both images (bgr8),
/// both camera infos (rectified: the right one's P[3] = -fx * baseline), the left camera's pose
/// on /tf (topics.world_frame -> camera_frame), and the mask and the disparity when the capture
/// has them. Throws
/// std::runtime_error naming the bag when it cannot be written.
void writeStereoBag(const std::filesystem::path& bag, const std::vector<host::Capture>& captures,
                    const StereoBagTopics& topics,
                    const std::string& camera_frame = "stereo_left_optical", double start_s = 1.0,
                    double period_s = 1.0);

/// Calls `each` with every usable stereo pair of the bag, in stamp order, as a capture: the pair
/// (converted to bgr8), its intrinsics from the camera infos (baseline from the right one's P),
/// T_world_camera from the bag's /tf and /tf_static at the left image's stamp, and the mask and
/// disparity of the same stamp when there are. A stamp's messages are gathered until the bag
/// holds an image stamped kGatherWindowS later (a recorder receives a pair's topics well within
/// that), so memory holds only that window of images. Returns what was read and skipped. Throws
/// std::runtime_error naming the bag, the topic, the stamp and the field for input that is not
/// a stereo bag (no image on a topic, an image whose size is not its camera info's, an encoding
/// that is not an image).
inline constexpr double kGatherWindowS = 1.0;

StereoBagStats readStereoBag(const std::filesystem::path& bag, const StereoBagTopics& topics,
                             const std::function<void(host::Capture&&)>& each);

}  // namespace fvp::ros
