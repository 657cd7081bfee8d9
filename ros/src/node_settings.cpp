#include "fvp/ros/node_settings.h"

#include <xmlrpcpp/XmlRpcValue.h>

#include <climits>
#include <cmath>
#include <set>
#include <stdexcept>

#include "fvp/host/nbv/run_fields.h"
#include "fvp/ros/joint_state_listener.h"

namespace fvp::ros {
namespace {

using XmlRpc::XmlRpcValue;

/// One parameter's reader: errors name it as a ROS user writes it.
class Param {
 public:
  Param(const ParamLookup& lookup, std::string key) : key_(std::move(key)) {
    present_ = lookup(key_, value_);
  }
  bool present() const { return present_; }

  [[noreturn]] void fail(const std::string& expected) const {
    throw std::invalid_argument("parameter '~" + key_ + "': expected " + expected + ", got " +
                                describe());
  }
  /// The value as a ROS user wrote it in YAML.
  std::string describe() const {
    switch (value_.getType()) {
      case XmlRpcValue::TypeInt:
        return std::to_string(static_cast<int>(value_));
      case XmlRpcValue::TypeDouble:
        return std::to_string(static_cast<double>(value_));
      case XmlRpcValue::TypeBoolean:
        return static_cast<bool>(value_) ? "true" : "false";
      case XmlRpcValue::TypeString: {
        std::string text = static_cast<std::string>(value_);
        if (text.size() > 60) text = text.substr(0, 60) + "...";
        return "'" + text + "'";
      }
      case XmlRpcValue::TypeArray:
        return "a list";
      case XmlRpcValue::TypeStruct:
        return "a dictionary";
      default:
        return "a value of another type";
    }
  }
  std::string text() const {
    if (value_.getType() != XmlRpcValue::TypeString) fail("a string");
    return static_cast<std::string>(value_);
  }
  double number() const {
    XmlRpcValue& v = value_;
    if (v.getType() == XmlRpcValue::TypeInt) return double(static_cast<int>(v));
    if (v.getType() != XmlRpcValue::TypeDouble || !std::isfinite(static_cast<double>(v)))
      fail("a finite number");
    return static_cast<double>(v);
  }
  int integer(int least) const {
    XmlRpcValue& v = value_;
    if (v.getType() != XmlRpcValue::TypeInt || static_cast<int>(v) < least)
      fail("an integer >= " + std::to_string(least));
    return static_cast<int>(v);
  }
  bool flag() const {
    XmlRpcValue& v = value_;
    if (v.getType() != XmlRpcValue::TypeBoolean) fail("true or false");
    return static_cast<bool>(v);
  }
  std::vector<std::string> texts() const {
    XmlRpcValue& v = value_;
    if (v.getType() != XmlRpcValue::TypeArray) fail("a list of strings");
    std::vector<std::string> out;
    for (int i = 0; i < v.size(); ++i) {
      if (v[i].getType() != XmlRpcValue::TypeString) fail("a list of strings");
      out.push_back(static_cast<std::string>(v[i]));
    }
    return out;
  }

 private:
  std::string key_;
  mutable XmlRpcValue value_;  // XmlRpc's casts are not const
  bool present_ = false;
};

// The run specification's settings, by their type.
void read(const Param& p, const host::nbv::RunField&, std::string& v) {
  v = p.text();
}
void read(const Param& p, const host::nbv::RunField&, std::filesystem::path& v) {
  v = p.text();
}
void read(const Param& p, const host::nbv::RunField&, std::uint64_t& v) {
  v = std::uint64_t(p.integer(0));
}
void read(const Param& p, const host::nbv::RunField&, int& v) {
  v = p.integer(1);
}
void read(const Param& p, const host::nbv::RunField&, bool& v) {
  v = p.flag();
}
void read(const Param& p, const host::nbv::RunField& field, double& v) {
  v = p.number();
  if (!(field.may_be_zero ? v >= 0.0 : v > 0.0))
    p.fail(field.may_be_zero ? "a finite number >= 0" : "a finite number > 0");
}
void read(const Param& p, const host::nbv::RunField&, std::optional<int>& v) {
  const int n = p.integer(0);  // 0: no limit, as the CLI's --max-views
  v = n > 0 ? std::optional<int>(n) : std::nullopt;
}
void read(const Param& p, const host::nbv::RunField&, accel::BackendChoice& v) {
  const auto choice = accel::parseBackendChoice(p.text());
  if (!choice) p.fail("one of " + accel::backendChoiceNames());
  v = *choice;
}
void read(const Param& p, const host::nbv::RunField&, host::nbv::StopRule& v) {
  const auto rule = host::nbv::stopRuleFromString(p.text());
  if (!rule) p.fail("one of " + host::nbv::stopRuleNames());
  v = *rule;
}

template <typename T>
void readIf(const ParamLookup& node, const std::string& key, T& value) {
  const Param p(node, key);
  if (!p.present()) return;
  if constexpr (std::is_same_v<T, std::string>) {
    value = p.text();
  } else if constexpr (std::is_same_v<T, bool>) {
    value = p.flag();
  } else {
    value = p.number();
  }
}

void readCamera(const ParamLookup& node, StereoTopicCameraOptions& camera) {
  std::string ns = "/stereo", world = camera.topics.world_frame;
  readIf(node, "stereo_ns", ns);
  readIf(node, "world_frame", world);
  camera.topics = StereoBagTopics::under(ns, world);
  readIf(node, "mask_topic", camera.topics.fruitlet_mask);
  readIf(node, "disparity_topic", camera.topics.disparity);
  readIf(node, "use_mask", camera.use_mask);
  readIf(node, "use_disparity", camera.use_disparity);
  readIf(node, "trigger_topic", camera.trigger_topic);
  readIf(node, "capture_timeout_s", camera.timeout_s);
  readIf(node, "tf_timeout_s", camera.tf_timeout_s);
  camera.validate();
}

void readArm(const ParamLookup& node, FvpNodeSettings& s) {
  readIf(node, "joint_states_topic", s.joint_states_topic);
  s.joint_names = defaultJointNames();
  if (const Param p(node, "joint_names"); p.present()) {
    s.joint_names = p.texts();
    const std::set<std::string> distinct(s.joint_names.begin(), s.joint_names.end());
    if (s.joint_names.size() != std::size_t(robot::kArmJoints) ||
        distinct.size() != s.joint_names.size())
      p.fail("7 distinct joint names (the slider's, then the UR5's six)");
  }
  readIf(node, "command_topic", s.commander.command_topic);
  readIf(node, "goal_tolerance", s.commander.goal_tolerance);
  readIf(node, "settle_timeout_s", s.commander.settle_timeout_s);
  s.commander.validate();
  std::string arm_config;
  readIf(node, "arm_config", arm_config);
  s.arm_config = arm_config;
  if (const Param p(node, "reproducible_motion_seed"); p.present())
    s.reproducible_motion_seed = std::uint64_t(p.integer(0));
}

}  // namespace

FvpNodeSettings readNodeSettings(const ::ros::NodeHandle& private_node) {
  return readNodeSettings([&private_node](const std::string& key, XmlRpc::XmlRpcValue& value) {
    return private_node.getParam(key, value);
  });
}

FvpNodeSettings readNodeSettings(const ParamLookup& node) {
  FvpNodeSettings s;
  host::nbv::visitSetupFields(s.setup, [&node](const host::nbv::RunField& field, auto& value) {
    const Param p(node, std::string(field.key));
    if (p.present()) read(p, field, value);
  });
  std::string perception_config;
  readIf(node, "perception_config", perception_config);
  if (!perception_config.empty())
    s.setup.perception = host::PerceptionConfig::fromYamlFile(perception_config);
  s.setup.validate();
  readCamera(node, s.camera);
  readArm(node, s);
  return s;
}

}  // namespace fvp::ros
