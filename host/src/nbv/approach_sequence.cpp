#include "fvp/host/nbv/approach_sequence.h"

#include <array>
#include <numbers>

#include "fvp/host/nbv/nbv_setup.h"

namespace fvp::host::nbv {
namespace {

// A cluster's start view and the same view from farther out: its camera body (3 cm) with
// the collision padding (1 cm) and a coarse voxel (1 cm) needs about 5 cm around it, and
// leaves may hang that close to the start view (the simulator keeps them 5 cm off the
// camera centre), so each step backs off by that much; 0.45 m is the farthest, where the
// 3 cm tag still spans about 70 px. Where none of those can be reached (the foliage an
// earlier cluster's views mapped may stand where the arm must), the same views turned about
// the vertical through the cluster's centre by 20 and then 40 degrees either way: the tag,
// tilted at most 5 degrees, is then seen 45 degrees off its axis at most, well inside what
// AprilTag detects.
constexpr double kApproachStepM = 0.05;
constexpr int kApproachSteps = 3;
constexpr std::array<double, 5> kApproachYawDeg = {0.0, 20.0, -20.0, 40.0, -40.0};

}  // namespace

std::vector<ApproachPose> approachPoses(const Eigen::Isometry3d& T_world_start_camera,
                                        const Eigen::Vector3d& center_m) {
  std::vector<ApproachPose> poses;
  const Eigen::Vector3d back = -T_world_start_camera.linear().col(2);
  for (const double yaw_deg : kApproachYawDeg) {
    const Eigen::Isometry3d turn =
        Eigen::Translation3d(center_m) *
        Eigen::AngleAxisd(yaw_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()) *
        Eigen::Translation3d(-center_m);
    for (int step = 0; step <= kApproachSteps; ++step) {
      Eigen::Isometry3d T = T_world_start_camera;
      T.translation() += step * kApproachStepM * back;
      poses.push_back({turn * T, yaw_deg});
    }
  }
  return poses;
}

ApproachSequence::ApproachSequence(const ClusterTarget& target)
    : target_(target), poses_(approachPoses(target.T_world_start_camera, target.center_m)) {}

bool ApproachSequence::moveToNext(Arm& arm, const LoopClock& clock, ClusterVisit& visit,
                                  TourResult& tour) {
  for (; next_ < poses_.size(); ++next_) {
    const auto& [T, yaw_deg] = poses_[next_];
    if (arm.cameraPose().isApprox(T, 1e-9) || !arm.reachable(T)) continue;
    const double before_s = clock.now_s();
    const MoveResult move = arm.moveTo(T);
    tour.transit_s += clock.now_s() - before_s;
    tour.transit_motion_s += move.motion_s;
    move_status_ = toString(move.status);
    ++tour.transit_motion[move_status_];
    if (move.ok()) {
      visit.approach_distance_m = (T.translation() - target_.center_m).norm();
      visit.approach_yaw_deg = yaw_deg;
      ++next_;
      return true;
    }
  }
  return false;
}

}  // namespace fvp::host::nbv
