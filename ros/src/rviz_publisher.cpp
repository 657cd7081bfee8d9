#include "fvp/ros/rviz_publisher.h"

#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "fvp/host/map/map_engine.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/ros/rviz_markers.h"
#include "fvp/ros/stereo_messages.h"

namespace fvp::ros {
namespace {

sensor_msgs::PointCloud2 cloudOf(const std::vector<Eigen::Vector3f>& points_m,
                                 const std::string& frame) {
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = frame;
  cloud.header.stamp = ::ros::Time::now();
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(points_m.size());
  // The iterators take the address of the first byte: none in an empty cloud (UBSan).
  if (points_m.empty()) return cloud;
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  for (const Eigen::Vector3f& p : points_m) {
    *x = p.x();
    *y = p.y();
    *z = p.z();
    ++x, ++y, ++z;
  }
  return cloud;
}

}  // namespace

RvizPublisher::RvizPublisher(::ros::NodeHandle& node, std::string world_frame)
    : world_frame_(std::move(world_frame)) {
  markers_ = node.advertise<visualization_msgs::MarkerArray>(RvizTopics::kMarkers, 10, true);
  occupied_ = node.advertise<sensor_msgs::PointCloud2>(RvizTopics::kOccupied, 1, true);
  surface_ = node.advertise<sensor_msgs::PointCloud2>(RvizTopics::kSurface, 1, true);
}

visualization_msgs::Marker RvizPublisher::marker(const std::string& ns, int id, int type) const {
  visualization_msgs::Marker m = rvizMarker(world_frame_, ns, id, type);
  m.header.stamp = ::ros::Time::now();
  return m;
}

void RvizPublisher::clear() {
  visualization_msgs::MarkerArray all;
  visualization_msgs::Marker wipe;
  wipe.header.frame_id = world_frame_;
  wipe.action = visualization_msgs::Marker::DELETEALL;
  all.markers.push_back(wipe);
  markers_.publish(all);
  path_m_.clear();
  occupied_m_.clear();
  surface_m_.clear();
  occupied_.publish(cloudOf(occupied_m_, world_frame_));
  surface_.publish(cloudOf(surface_m_, world_frame_));
  next_id_ = 0;
}

void RvizPublisher::onView(const host::nbv::ViewEvent& event) {
  path_m_.push_back(event.T_world_camera.translation());
  visualization_msgs::MarkerArray out;
  out.markers.push_back(cameraPathMarker(path_m_, world_frame_));
  out.markers.push_back(viewMarker(event.T_world_camera, world_frame_, int(path_m_.size()) - 1));
  markers_.publish(out);
}

void RvizPublisher::onPlan(const host::nbv::PlanEvent& event) {
  if (!event.step) return;
  visualization_msgs::Marker candidates =
      marker("candidates", 0, visualization_msgs::Marker::SPHERE_LIST);
  candidates.scale.x = candidates.scale.y = candidates.scale.z = 0.006;
  for (const host::planner::Candidate& c : event.step->candidates) {
    candidates.points.push_back(pointMsg(c.position_m()));
    candidates.colors.push_back(c.reachable ? rvizColour(1.0f, 0.8f, 0.1f, 0.8f)
                                            : rvizColour(0.5f, 0.5f, 0.5f, 0.4f));
  }
  visualization_msgs::MarkerArray out;
  out.markers.push_back(candidates);
  if (event.step->chosen) {
    const auto& T = event.step->candidates[*event.step->chosen].T_world_camera;
    visualization_msgs::Marker chosen = marker("chosen_view", 0, visualization_msgs::Marker::ARROW);
    chosen.points = {pointMsg(T.translation()), pointMsg(T * Eigen::Vector3d(0.0, 0.0, 0.15))};
    chosen.scale.x = 0.008;
    chosen.scale.y = 0.016;
    chosen.color = rvizColour(1.0f, 0.5f, 0.0f, 1.0f);
    out.markers.push_back(chosen);
  }
  markers_.publish(out);
}

void RvizPublisher::onClusterDone(const host::nbv::ClusterVisit& visit,
                                  const host::nbv::ClusterWork& work) {
  const host::MappingSession& session = *work.session;
  visualization_msgs::MarkerArray out;
  const int k = int(visit.index);
  if (session.region()) {
    visualization_msgs::Marker region =
        marker("cluster_regions", k, visualization_msgs::Marker::SPHERE);
    region.pose.position = pointMsg(session.region()->center_m());
    region.scale.x = region.scale.y = region.scale.z = 2.0 * session.region()->radius_m();
    region.color = rvizColour(0.6f, 0.3f, 0.9f, 0.15f);
    out.markers.push_back(region);
  }
  if (session.T_world_tag()) {
    visualization_msgs::Marker tag = marker("tags", k, visualization_msgs::Marker::CUBE);
    tag.pose = poseMsg(*session.T_world_tag());
    tag.scale.x = tag.scale.y = 0.04;  // about a printed tag's side; its frame's z is its normal
    tag.scale.z = 0.002;
    tag.color = rvizColour(0.1f, 0.1f, 0.1f, 1.0f);
    out.markers.push_back(tag);
  }
  if (visit.run) {
    const host::sizing::SizingResult& sizing = visit.run->sizing;
    for (const auto& f : sizing.fruitlets)
      addFruitletMarkers(out, f.center_m, f.size_mm, true, world_frame_, next_id_++);
    for (const auto& f : sizing.unsupported)
      addFruitletMarkers(out, f.center_m, f.size_mm, false, world_frame_, next_id_++);
  }
  markers_.publish(out);
  if (const host::map::MapEngine* map = session.map()) {
    const host::map::GridGeometry& grid = map->gridGeometry(host::map::MapLevel::kFine);
    for (const auto& index : map->occupiedVoxels(host::map::MapLevel::kFine))
      occupied_m_.push_back(grid.voxelCenter_m(index).cast<float>());
    occupied_.publish(cloudOf(occupied_m_, world_frame_));
  }
  const std::vector<Eigen::Vector3f> surface = session.surfacePoints();
  surface_m_.insert(surface_m_.end(), surface.begin(), surface.end());
  surface_.publish(cloudOf(surface_m_, world_frame_));
}

}  // namespace fvp::ros
