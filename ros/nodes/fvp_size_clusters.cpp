// A command-line client of the fvp node's action (docs/ros.md): sends a size_clusters goal and
// prints the sized fruitlets, optionally writing them as JSON. The clusters come from the
// simulator bridge's ~clusters table (--from-bridge) or from AprilTag ids (--tags: start from
// where the camera is for one, or give the node its approach from the table).
#include <actionlib/client/simple_action_client.h>
#include <fvp_ros/SizeClustersAction.h>
#include <ros/ros.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "fvp/host/core/atomic_file.h"
#include "fvp/ros/size_clusters_server.h"

namespace {

nlohmann::json resultJson(const fvp_ros::SizeClustersResult& r) {
  nlohmann::json out = {{"views", r.views},
                        {"time_s", r.time_s},
                        {"dropped_frames", r.dropped_frames},
                        {"fruitlets", nlohmann::json::array()},
                        {"clusters", nlohmann::json::array()}};
  for (const auto& f : r.fruitlets)
    out["fruitlets"].push_back({{"cluster_index", f.cluster_index},
                                {"center_m", {f.center.x, f.center.y, f.center.z}},
                                {"diameter_mm", f.diameter_mm},
                                {"points", f.points},
                                {"well_seen_images", f.well_seen_images}});
  for (const auto& c : r.clusters) {
    nlohmann::json path = nlohmann::json::array();
    for (const auto& p : c.camera_poses) path.push_back({p.position.x, p.position.y, p.position.z});
    out["clusters"].push_back({{"cluster_index", c.cluster_index},
                               {"status", c.status},
                               {"stop_reason", c.stop_reason},
                               {"views", c.views},
                               {"arrival_s", c.arrival_s},
                               {"loop_start_s", c.loop_start_s},
                               {"camera_path_m", path}});
  }
  return out;
}

int run(const std::string& action, const std::string& bridge, const std::vector<int>& tags,
        const std::string& out, double timeout_s) {
  ros::NodeHandle node;
  fvp_ros::SizeClustersGoal goal;
  if (!bridge.empty()) {
    XmlRpc::XmlRpcValue table;
    if (!node.getParam(bridge + "/clusters", table))
      throw std::runtime_error(bridge + "/clusters: no such parameter (is the bridge running?)");
    goal = fvp::ros::goalOfClusterTable(table);
  }
  for (const int tag : tags) {
    fvp_ros::ClusterGoal c;  // start pose all zero: from where the camera is
    c.use_tag_id = true;
    c.tag_id = tag;
    goal.clusters.push_back(c);
  }
  actionlib::SimpleActionClient<fvp_ros::SizeClustersAction> client(action, true);
  if (!client.waitForServer(ros::Duration(timeout_s)))
    throw std::runtime_error(action + ": no action server");
  client.sendGoal(goal);
  if (!client.waitForResult(ros::Duration(timeout_s)))
    throw std::runtime_error(action + ": no result within " + std::to_string(timeout_s) + " s");
  const auto state = client.getState();
  const fvp_ros::SizeClustersResult result = *client.getResult();
  std::printf("%s: %s, %u views, %.1f s\n", action.c_str(), state.toString().c_str(), result.views,
              result.time_s);
  for (const auto& f : result.fruitlets)
    std::printf("cluster %u  %6.2f mm  at (%.4f, %.4f, %.4f) m\n", f.cluster_index, f.diameter_mm,
                f.center.x, f.center.y, f.center.z);
  if (!out.empty())
    fvp::host::writeFileAtomically(out, "the result", [&](std::ostream& s) {
      s << resultJson(result).dump(2) << "\n";
      return bool(s);
    });
  return state == actionlib::SimpleClientGoalState::SUCCEEDED ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "fvp_size_clusters", ros::init_options::AnonymousName);
  CLI::App app{"Send the fvp node a size_clusters goal and print the sized fruitlets"};
  std::string action = "/fvp/size_clusters", bridge, out;
  std::vector<int> tags;
  double timeout_s = 3600.0;
  app.add_option("--action", action, "the fvp node's action")->capture_default_str();
  app.add_option("--from-bridge", bridge,
                 "the simulator bridge node (e.g. /fvp_sim_bridge): its world's clusters");
  app.add_option("--tags", tags, "AprilTag ids of clusters, each from where the camera is");
  app.add_option("--out", out, "write the result as JSON here");
  app.add_option("--timeout-s", timeout_s,
                 "seconds of ROS time to wait (simulated time under the bridge)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (bridge.empty() && tags.empty()) {
    std::cerr << "fvp_size_clusters: give --from-bridge or --tags\n";
    return 2;
  }
  try {
    return run(action, bridge, tags, out, timeout_s);
  } catch (const std::exception& e) {
    std::cerr << "fvp_size_clusters: " << e.what() << "\n";
    return 2;
  }
}
