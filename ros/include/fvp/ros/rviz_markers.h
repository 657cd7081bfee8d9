// The RViz markers fvp draws (docs/ros.md, "RViz"), built once for the node's live topics
// (RvizPublisher) and for a recorded trial's bag (StereoBagWriter::addMarkers). C++17, as ROS 1's
// message headers are.
#pragma once

#include <visualization_msgs/MarkerArray.h>

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace fvp::ros {

std_msgs::ColorRGBA rvizColour(float r, float g, float b, float a);
/// A marker of `type` in `frame` (stamp 0: the latest transform), identity pose.
visualization_msgs::Marker rvizMarker(const std::string& frame, const std::string& ns, int id,
                                      int type);
/// A sized detection: a sphere of its diameter ("fruitlets" green, or "dropped_detections" red
/// for one the support rule dropped) and a label of its size above it ("fruitlet_sizes" /
/// "dropped_sizes"); both with `id`.
void addFruitletMarkers(visualization_msgs::MarkerArray& out, const Eigen::Vector3d& center_m,
                        double size_mm, bool kept, const std::string& frame, int id);
/// The camera path ("camera_path", a line through the view positions).
visualization_msgs::Marker cameraPathMarker(const std::vector<Eigen::Vector3d>& path_m,
                                            const std::string& frame);
/// A view ("views"): an arrow 10 cm along the camera's optical axis.
visualization_msgs::Marker viewMarker(const Eigen::Isometry3d& T_world_camera,
                                      const std::string& frame, int id);

}  // namespace fvp::ros
