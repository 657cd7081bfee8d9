#include "fvp/ros/size_clusters_server.h"

#include <ros/console.h>

#include <cmath>
#include <stdexcept>

#include "fvp/host/session/mapping_session.h"
#include "fvp/ros/ros_loop_clock.h"
#include "fvp/ros/stereo_messages.h"

namespace fvp::ros {
namespace {

Eigen::Vector3d vectorOf(const geometry_msgs::Point& p) {
  return {p.x, p.y, p.z};
}

bool finite(const geometry_msgs::Point& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

fvp_ros::SizedFruitlet sizedFruitlet(const host::sizing::FruitletEstimate& f, std::size_t cluster) {
  fvp_ros::SizedFruitlet out;
  out.cluster_index = std::uint32_t(cluster);
  out.center = pointMsg(f.center_m);
  out.diameter_mm = f.size_mm;
  out.points = std::uint32_t(f.points);
  out.well_seen_images = std::uint32_t(f.support.well_seen_images);
  return out;
}

/// Feedback after every view and every cluster, and the RViz picture.
class GoalObserver : public host::nbv::TourObserver {
 public:
  GoalObserver(actionlib::SimpleActionServer<fvp_ros::SizeClustersAction>& server,
               const host::nbv::LoopClock& clock, RvizPublisher* rviz)
      : server_(server), clock_(clock), rviz_(rviz) {}

  void onClusterStart(std::size_t index, const host::nbv::ClusterTarget& target) override {
    feedback_.cluster_index = std::uint32_t(index);
    if (rviz_) rviz_->onClusterStart(index, target);
  }
  void onView(const host::nbv::ViewEvent& event) override {
    ++feedback_.views;
    if (rviz_) rviz_->onView(event);
    publish();
  }
  void onPlan(const host::nbv::PlanEvent& event) override {
    if (rviz_) rviz_->onPlan(event);
  }
  void onClusterDone(const host::nbv::ClusterVisit& visit,
                     const host::nbv::ClusterWork& work) override {
    if (visit.run)
      for (const auto& f : visit.run->sizing.fruitlets)
        feedback_.sizes.push_back(sizedFruitlet(f, visit.index));
    if (rviz_) rviz_->onClusterDone(visit, work);
    publish();
  }

 private:
  void publish() {
    feedback_.time_s = clock_.now_s();
    server_.publishFeedback(feedback_);
  }

  actionlib::SimpleActionServer<fvp_ros::SizeClustersAction>& server_;
  const host::nbv::LoopClock& clock_;
  RvizPublisher* rviz_;
  fvp_ros::SizeClustersFeedback feedback_;
};

}  // namespace

std::vector<host::nbv::ClusterTarget> targetsOfGoal(const fvp_ros::SizeClustersGoal& goal,
                                                    const Eigen::Isometry3d& T_world_camera_now) {
  if (goal.clusters.empty())
    throw std::invalid_argument("goal: expected at least one cluster in 'clusters'");
  std::vector<host::nbv::ClusterTarget> targets;
  for (std::size_t k = 0; k < goal.clusters.size(); ++k) {
    const fvp_ros::ClusterGoal& c = goal.clusters[k];
    const std::string where = "goal: clusters[" + std::to_string(k) + "]";
    host::nbv::ClusterTarget t;
    if (c.use_tag_id) {
      if (c.tag_id < -1)
        throw std::invalid_argument(where + ".tag_id: expected an id >= 0, or -1 (any tag)");
      t.tag_id = c.tag_id;
    }
    if (c.use_region_center) {
      if (!finite(c.region_center))
        throw std::invalid_argument(where + ".region_center: expected a finite point");
      t.region_center_m = vectorOf(c.region_center);
    }
    const auto& q = c.start_camera_pose.orientation;
    const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (norm == 0.0) {
      t.T_world_start_camera = T_world_camera_now;
    } else {
      if (!(std::abs(norm - 1.0) < 1e-3) || !finite(c.start_camera_pose.position))
        throw std::invalid_argument(where +
                                    ".start_camera_pose: expected a finite position and a unit "
                                    "quaternion (all zero: from where the camera is)");
      t.T_world_start_camera = Eigen::Isometry3d::Identity();
      t.T_world_start_camera.translation() = vectorOf(c.start_camera_pose.position);
      t.T_world_start_camera.linear() =
          Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
    }
    if (!finite(c.center)) throw std::invalid_argument(where + ".center: expected a finite point");
    t.center_m = vectorOf(c.center);
    targets.push_back(t);
  }
  return targets;
}

fvp_ros::SizeClustersGoal goalOfClusterTable(XmlRpc::XmlRpcValue& table) {
  const std::string expected = "~clusters: expected a list of rows of 11 numbers";
  if (table.getType() != XmlRpc::XmlRpcValue::TypeArray || table.size() == 0)
    throw std::invalid_argument(expected);
  fvp_ros::SizeClustersGoal goal;
  for (int k = 0; k < table.size(); ++k) {
    XmlRpc::XmlRpcValue& row = table[k];
    if (row.getType() != XmlRpc::XmlRpcValue::TypeArray || row.size() != 11)
      throw std::invalid_argument(expected);
    double v[11];
    for (int i = 0; i < 11; ++i) {
      if (row[i].getType() != XmlRpc::XmlRpcValue::TypeDouble)
        throw std::invalid_argument(expected);
      v[i] = static_cast<double>(row[i]);
    }
    fvp_ros::ClusterGoal c;
    c.use_tag_id = table.size() > 1;
    c.tag_id = int(v[0]);
    c.start_camera_pose.position = pointMsg({v[1], v[2], v[3]});
    c.start_camera_pose.orientation.x = v[4];
    c.start_camera_pose.orientation.y = v[5];
    c.start_camera_pose.orientation.z = v[6];
    c.start_camera_pose.orientation.w = v[7];
    c.center = pointMsg({v[8], v[9], v[10]});
    goal.clusters.push_back(c);
  }
  return goal;
}

fvp_ros::SizeClustersResult resultOfTour(const host::nbv::TourResult& tour,
                                         std::size_t goal_clusters, double time_s) {
  fvp_ros::SizeClustersResult result;
  std::vector<bool> visited(goal_clusters, false);
  for (const host::nbv::ClusterVisit& visit : tour.visits) {
    fvp_ros::ClusterOutcome outcome;
    outcome.cluster_index = std::uint32_t(visit.index);
    if (visit.index < visited.size()) visited[visit.index] = true;
    outcome.status = host::nbv::toString(visit.status);
    if (visit.run && visit.run->run.stop_reason == "cancelled") outcome.status = "cancelled";
    outcome.arrival_s = visit.arrival_s;
    outcome.loop_start_s = visit.loop_start_s;
    if (visit.run) {
      outcome.stop_reason = visit.run->run.stop_reason;
      outcome.views = std::uint32_t(visit.run->run.views);
      for (const Eigen::Isometry3d& T : visit.run->run.camera_poses)
        outcome.camera_poses.push_back(poseMsg(T));
      result.views += outcome.views;
      result.dropped_frames += std::uint32_t(visit.run->run.events.dropped_frames);
      for (const auto& f : visit.run->sizing.fruitlets)
        result.fruitlets.push_back(sizedFruitlet(f, visit.index));
    }
    result.clusters.push_back(outcome);
  }
  for (std::size_t k = 0; k < visited.size(); ++k) {
    if (visited[k]) continue;
    fvp_ros::ClusterOutcome outcome;  // a cancel ended the tour before it
    outcome.cluster_index = std::uint32_t(k);
    outcome.status = "not_visited";
    result.clusters.push_back(outcome);
  }
  result.time_s = time_s;
  return result;
}

SizeClustersServer::SizeClustersServer(::ros::NodeHandle& node, const std::string& action_name,
                                       host::nbv::NbvSetupOptions options,
                                       host::nbv::Camera& camera, host::nbv::Arm& arm,
                                       RvizPublisher* rviz)
    : camera_(camera),
      arm_(arm),
      rviz_(rviz),
      server_(
          node, action_name,
          [this](const fvp_ros::SizeClustersGoalConstPtr& goal) { execute(goal); }, false) {
  options.stop.cancel = [this] { return server_.isPreemptRequested() || !::ros::ok(); };
  setup_ = std::make_unique<host::nbv::NbvSetup>(std::move(options));
  server_.start();
}

void SizeClustersServer::execute(const fvp_ros::SizeClustersGoalConstPtr& goal) {
  std::vector<host::nbv::ClusterTarget> targets;
  try {
    targets = targetsOfGoal(*goal, arm_.cameraPose());
  } catch (const std::exception& e) {  // a bad goal, or no joint states yet
    ROS_ERROR_STREAM("size_clusters: goal aborted: " << e.what());
    server_.setAborted(fvp_ros::SizeClustersResult(), e.what());
    return;
  }
  RosLoopClock clock;
  if (rviz_) rviz_->clear();
  GoalObserver observer(server_, clock, rviz_);
  host::nbv::TourResult tour;
  try {
    tour = setup_->runTour({camera_, arm_, clock}, targets, &observer);
  } catch (const std::exception& e) {  // the arm's driver broke, a backend failed
    ROS_ERROR_STREAM("size_clusters: goal aborted: " << e.what());
    server_.setAborted(fvp_ros::SizeClustersResult(), e.what());
    return;
  }
  const fvp_ros::SizeClustersResult result = resultOfTour(tour, targets.size(), clock.now_s());
  if (server_.isPreemptRequested())
    server_.setPreempted(result, "cancelled");
  else
    server_.setSucceeded(result);
}

}  // namespace fvp::ros
