// The simulator bridge node (docs/ros.md): a simulated world, camera and arm behind a robot's
// topics (SimBridge), with /clock, so the fvp node runs over ROS on any machine. Its private
// parameter ~clusters lists the world's clusters (tag id, start view, centre) for a client's goal.
#include <ros/ros.h>

#include <iostream>

#include "fvp/robot/sim/sim_clock.h"
#include "fvp/ros/sim_bridge.h"

namespace {

template <typename T>
void readIf(const ros::NodeHandle& node, const std::string& key, T& value) {
  if (node.hasParam(key) && !node.getParam(key, value))
    throw std::invalid_argument("parameter '~" + key + "': expected a value of its type");
}

fvp::ros::SimBridgeOptions optionsOf(const ros::NodeHandle& node) {
  fvp::ros::SimBridgeOptions o;
  int seed = 1;
  readIf(node, "seed", seed);
  if (seed < 0) throw std::invalid_argument("parameter '~seed': expected an integer >= 0");
  o.robot.seed = std::uint64_t(seed);
  std::string world, arm, clock = "wall", ns = "/stereo", world_frame = "world";
  readIf(node, "world_config", world);
  readIf(node, "arm_config", arm);
  readIf(node, "clock", clock);
  o.robot.world_config = world;
  o.robot.arm_config = arm;
  o.robot.clock = fvp::robot::sim::SimClock::modeFromString(clock);
  double day = -1.0;
  readIf(node, "season_day", day);
  if (day >= 0.0) o.robot.season_day = day;
  readIf(node, "stereo_ns", ns);
  readIf(node, "world_frame", world_frame);
  o.topics = fvp::ros::StereoBagTopics::under(ns, world_frame);
  readIf(node, "camera_frame", o.camera_frame);
  readIf(node, "trigger_topic", o.trigger_topic);
  readIf(node, "command_topic", o.command_topic);
  readIf(node, "joint_states_topic", o.joint_states_topic);
  readIf(node, "joint_names", o.joint_names);
  readIf(node, "publish_rate_hz", o.publish_rate_hz);
  o.robot.on_warning = [](const std::string& text) { ROS_WARN_STREAM(text); };
  return o;
}

int run() {
  ros::NodeHandle node, private_node("~");
  const fvp::ros::SimBridgeOptions options = optionsOf(private_node);
  fvp::ros::SimBridge bridge(node, options);
  // 17 significant digits: a double read back from the parameter server is the same double
  // (XmlRpc's default, 16, is not), so a goal of these poses is the world's own.
  XmlRpc::XmlRpcValue::setDoubleFormat("%.17g");
  XmlRpc::XmlRpcValue clusters;
  clusters.setSize(0);
  int k = 0;
  for (const std::vector<double>& row : bridge.clusterTable()) {
    XmlRpc::XmlRpcValue values;
    values.setSize(int(row.size()));
    for (std::size_t i = 0; i < row.size(); ++i) values[int(i)] = row[i];
    clusters[k++] = values;
  }
  private_node.setParam("clusters", clusters);
  ros::AsyncSpinner spinner(1);  // one event at a time, as one arm and one camera do
  spinner.start();
  ros::WallRate rate(options.publish_rate_hz);
  while (ros::ok()) {
    bridge.publishState();
    rate.sleep();
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "fvp_sim_bridge");
  try {
    return run();
  } catch (const std::exception& e) {
    ROS_FATAL_STREAM("fvp_sim_bridge: " << e.what());
    std::cerr << "fvp_sim_bridge: " << e.what() << "\n";
    return 2;
  }
}
