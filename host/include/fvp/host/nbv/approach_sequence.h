// A cluster's approach views, tried in order by a tour (docs/nbv-loop.md, "Tour"): its start
// view, the same view backed off along its axis, then those turned about the vertical through
// the cluster's centre. Each moveToNext moves the arm to the next one it can reach.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

#include "fvp/host/nbv/arm.h"
#include "fvp/host/nbv/loop_clock.h"

namespace fvp::host::nbv {

struct ClusterTarget;
struct ClusterVisit;
struct TourResult;

struct ApproachPose {
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  double yaw_deg = 0.0;  ///< turned about the vertical through the cluster's centre
};

/// The approach views of a cluster, in the order a tour tries them.
std::vector<ApproachPose> approachPoses(const Eigen::Isometry3d& T_world_start_camera,
                                        const Eigen::Vector3d& center_m);

class ApproachSequence {
 public:
  /// target must outlive the sequence.
  explicit ApproachSequence(const ClusterTarget& target);

  /// Moves to the next approach view the arm reports reachable; the move's time counts as
  /// the tour's transit. False when none is left; a success records the view in `visit`.
  bool moveToNext(Arm& arm, const LoopClock& clock, ClusterVisit& visit, TourResult& tour);

  /// The last move's status, "unreachable" when none was tried.
  const std::string& lastMoveStatus() const { return move_status_; }

 private:
  const ClusterTarget& target_;
  std::vector<ApproachPose> poses_;
  std::size_t next_ = 0;
  std::string move_status_ = "unreachable";
};

}  // namespace fvp::host::nbv
