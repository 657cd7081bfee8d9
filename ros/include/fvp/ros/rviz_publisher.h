// What the fvp node shows in RViz (docs/ros.md, "RViz"): a tour observer that publishes, in the
// world frame, the camera path and each chosen view, the candidate views of the last planning
// iteration, and per cluster when it is done its Cluster Region, its tag, the sized fruitlets
// (spheres of their diameter with size labels; detections the support rule dropped in red), the
// fine map's occupied voxels and the TSDF surface as point clouds. C++17.
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <visualization_msgs/MarkerArray.h>

#include <string>
#include <vector>

#include "fvp/host/nbv/nbv_setup.h"

namespace fvp::ros {

/// The topics, under the node's private namespace.
struct RvizTopics {
  static constexpr const char* kMarkers = "markers";           ///< MarkerArray
  static constexpr const char* kOccupied = "occupied_voxels";  ///< PointCloud2, latched
  static constexpr const char* kSurface = "tsdf_surface";      ///< PointCloud2, latched
};

class RvizPublisher : public host::nbv::TourObserver {
 public:
  RvizPublisher(::ros::NodeHandle& private_node, std::string world_frame);

  /// Forgets the last goal's markers (a new goal starts a new picture).
  void clear();
  void onView(const host::nbv::ViewEvent& event) override;
  void onPlan(const host::nbv::PlanEvent& event) override;
  void onClusterDone(const host::nbv::ClusterVisit& visit,
                     const host::nbv::ClusterWork& work) override;

 private:
  visualization_msgs::Marker marker(const std::string& ns, int id, int type) const;

  std::string world_frame_;
  ::ros::Publisher markers_, occupied_, surface_;
  std::vector<Eigen::Vector3d> path_m_;
  std::vector<Eigen::Vector3f> occupied_m_, surface_m_;  ///< of every cluster done so far
  int next_id_ = 0;
};

}  // namespace fvp::ros
