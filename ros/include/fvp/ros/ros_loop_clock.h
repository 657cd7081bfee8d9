// The next-best-view loop's clock on ROS time (docs/ros.md): wall time on a robot, the
// simulator bridge's /clock with use_sim_time. It counts compute as it happens, so nothing is
// charged. C++17.
#pragma once

#include <ros/time.h>

#include "fvp/host/nbv/loop_clock.h"

namespace fvp::ros {

class RosLoopClock : public host::nbv::LoopClock {
 public:
  /// Seconds are counted from construction.
  RosLoopClock() : start_(::ros::Time::now()) {}
  double now_s() const override { return (::ros::Time::now() - start_).toSec(); }

 private:
  ::ros::Time start_;
};

}  // namespace fvp::ros
