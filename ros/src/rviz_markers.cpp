#include "fvp/ros/rviz_markers.h"

#include <cstdio>

#include "fvp/ros/stereo_messages.h"

namespace fvp::ros {
std_msgs::ColorRGBA rvizColour(float r, float g, float b, float a) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

visualization_msgs::Marker rvizMarker(const std::string& frame, const std::string& ns, int id,
                                      int type) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  return m;
}

void addFruitletMarkers(visualization_msgs::MarkerArray& out, const Eigen::Vector3d& center_m,
                        double size_mm, bool kept, const std::string& frame, int id) {
  visualization_msgs::Marker sphere = rvizMarker(frame, kept ? "fruitlets" : "dropped_detections",
                                                 id, visualization_msgs::Marker::SPHERE);
  sphere.pose.position = pointMsg(center_m);
  sphere.scale.x = sphere.scale.y = sphere.scale.z = size_mm * 1e-3;
  sphere.color = kept ? rvizColour(0.2f, 0.8f, 0.2f, 0.8f) : rvizColour(0.9f, 0.2f, 0.2f, 0.4f);
  out.markers.push_back(sphere);
  visualization_msgs::Marker label = rvizMarker(frame, kept ? "fruitlet_sizes" : "dropped_sizes",
                                                id, visualization_msgs::Marker::TEXT_VIEW_FACING);
  label.pose.position = pointMsg(center_m + Eigen::Vector3d(0.0, 0.0, 0.02));
  label.scale.z = 0.012;
  label.color = kept ? rvizColour(1.0f, 1.0f, 1.0f, 1.0f) : rvizColour(1.0f, 0.5f, 0.5f, 1.0f);
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f mm", size_mm);
  label.text = text;
  out.markers.push_back(label);
}

visualization_msgs::Marker cameraPathMarker(const std::vector<Eigen::Vector3d>& path_m,
                                            const std::string& frame) {
  visualization_msgs::Marker path =
      rvizMarker(frame, "camera_path", 0, visualization_msgs::Marker::LINE_STRIP);
  path.scale.x = 0.005;
  path.color = rvizColour(0.2f, 0.5f, 1.0f, 1.0f);
  for (const Eigen::Vector3d& p : path_m) path.points.push_back(pointMsg(p));
  return path;
}

visualization_msgs::Marker viewMarker(const Eigen::Isometry3d& T_world_camera,
                                      const std::string& frame, int id) {
  visualization_msgs::Marker view =
      rvizMarker(frame, "views", id, visualization_msgs::Marker::ARROW);
  view.points = {pointMsg(T_world_camera.translation()),
                 pointMsg(T_world_camera * Eigen::Vector3d(0.0, 0.0, 0.1))};
  view.scale.x = 0.006;
  view.scale.y = 0.012;
  view.color = rvizColour(0.2f, 0.5f, 1.0f, 1.0f);
  return view;
}

}  // namespace fvp::ros
