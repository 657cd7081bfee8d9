#include <stdexcept>
#include <string>

#include "fvp/host/map/map_config.h"
#include "fvp/host/map/occupancy_model.h"

namespace fvp::host::map {
namespace {

void requireRange(double value, double lo, double hi, const std::string& field, bool open = true) {
  const bool ok = open ? (value > lo && value < hi) : (value >= lo && value <= hi);
  if (!ok) {
    throw std::invalid_argument(field + " = " + std::to_string(value) + ": expected a value in " +
                                (open ? "(" : "[") + std::to_string(lo) + ", " + std::to_string(hi) +
                                (open ? ")" : "]"));
  }
}

}  // namespace

void OccupancyModel::validate(const std::string& source) const {
  requireRange(prob_hit, 0.5, 1.0, source + ".prob_hit");
  requireRange(prob_miss, 0.0, 0.5, source + ".prob_miss");
  requireRange(clamp_min, 0.0, 0.5, source + ".clamp_min");
  requireRange(clamp_max, 0.5, 1.0, source + ".clamp_max");
  requireRange(occupied_prob, clamp_min, clamp_max, source + ".occupied_prob");
}

void MapConfig::validate(const std::string& source) const {
  requireRange(coarse_voxel_size_m, 1e-4, 1.0, source + ".coarse_voxel_size_m");
  requireRange(fine_voxel_size_m, 1e-4, 1.0, source + ".fine_voxel_size_m");
  requireRange(sensor_max_range_m, 0.0, 100.0, source + ".sensor_max_range_m");
  for (int a = 0; a < 3; ++a) {
    if (!(observation_max_m[a] > observation_min_m[a]) || !observation_min_m.allFinite() ||
        !observation_max_m.allFinite()) {
      throw std::invalid_argument(source + ".observation_max_m must exceed " + source +
                                  ".observation_min_m on every axis");
    }
  }
  model.validate(source + ".model");
}

}  // namespace fvp::host::map
