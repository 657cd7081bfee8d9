#include "fvp/robot/sim/camera_views.h"

#include "fvp/host/core/look_at.h"

#include <cmath>
#include <stdexcept>

namespace fvp::robot::sim {

Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye_m, const Eigen::Vector3d& target_m) {
  return host::lookAtPose(eye_m, target_m);
}

std::vector<Eigen::Isometry3d> orbitViews(const World& world, int count, double arc_deg) {
  if (count < 1) throw std::invalid_argument("orbitViews: count must be at least 1");
  if (!(arc_deg >= 0.0 && arc_deg <= 360.0))
    throw std::invalid_argument("orbitViews: arc_deg must be in [0, 360]");
  const Eigen::Vector3d target = world.clusterCenter_m();
  const Eigen::Vector3d offset = world.startCameraPose().translation() - target;
  std::vector<Eigen::Isometry3d> views;
  for (int i = 0; i < count; ++i) {
    const double t = count == 1 ? 0.0 : static_cast<double>(i) / (count - 1) - 0.5;
    const double angle = t * arc_deg * M_PI / 180.0;
    const Eigen::Vector3d eye =
        target + Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()) * offset;
    views.push_back(lookAt(eye, target));
  }
  return views;
}

}  // namespace fvp::robot::sim
