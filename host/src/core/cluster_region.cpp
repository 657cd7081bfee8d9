#include "fvp/host/core/cluster_region.h"

#include <cmath>
#include <stdexcept>

namespace fvp::host {

void ClusterRegionConfig::validate() const {
  if (!(radius_m > 0.0) || !std::isfinite(radius_m))
    throw std::invalid_argument("cluster region config: radius_m: expected a positive radius");
  if (!center_offset_tag_m.allFinite())
    throw std::invalid_argument("cluster region config: center_offset_tag_m: expected finite");
  if (center_m && !center_m->allFinite())
    throw std::invalid_argument("cluster region config: center_m: expected finite");
}

ClusterRegion ClusterRegion::fromTag(const Eigen::Isometry3d& T_world_tag,
                                     const ClusterRegionConfig& config) {
  config.validate();
  return ClusterRegion(T_world_tag * config.center_offset_tag_m, config.radius_m);
}

}  // namespace fvp::host
