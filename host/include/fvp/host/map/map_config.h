// Geometry and sensor model of the coarse and fine maps (docs/design.md section 5, issue 4).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>

#include "fvp/host/map/occupancy_model.h"

namespace fvp::host::map {

inline constexpr double kDefaultCoarseVoxelSizeM = 0.01;
inline constexpr double kDefaultFineVoxelSizeM = 0.001;
inline constexpr double kDefaultSensorMaxRangeM = 1.0;

/// Where the fine map's rays update voxels. The planners read the fine map only inside the
/// Cluster Region either way; kObservationBox is RVP's setting in the paper (one 1 mm ROI
/// octree over the whole observation space) and costs what that map costs to update.
enum class FineMapExtent { kClusterRegion, kObservationBox };

/// "cluster_region" / "observation_box"; parse throws std::invalid_argument naming `field`.
std::string toString(FineMapExtent extent);
FineMapExtent parseFineMapExtent(const std::string& text, const std::string& field);

struct MapConfig {
  /// Coarse map: whole observation space. The box is snapped outward to whole voxels of
  /// the OctoMap key lattice (voxel k covers [k, k+1) * voxel size).
  double coarse_voxel_size_m = kDefaultCoarseVoxelSizeM;
  Eigen::Vector3d observation_min_m{-1.0, -1.0, 0.0};
  Eigen::Vector3d observation_max_m{1.0, 1.0, 2.0};
  /// Fine map: occupancy + ROI, inside the Cluster Region sphere (see fine_map_extent).
  double fine_voxel_size_m = kDefaultFineVoxelSizeM;
  /// kObservationBox: the fine map is updated over the whole observation box (octomap
  /// engine only; the grid engine's fine map is the Cluster Region's cube).
  FineMapExtent fine_map_extent = FineMapExtent::kClusterRegion;
  /// Points farther than this from the sensor: the ray is cut at this range and its end
  /// is not a hit (OctoMap's maxrange).
  double sensor_max_range_m = kDefaultSensorMaxRangeM;
  OccupancyModel model;

  /// Throws std::invalid_argument naming `source`.field and the expected range.
  void validate(const std::string& source = "map config") const;

  /// Reads a YAML file (keys and defaults: host/config/map_default.yaml); missing keys keep
  /// their defaults. Unknown keys, wrong types and out-of-range values throw
  /// std::invalid_argument naming the file and the key.
  static MapConfig fromYamlFile(const std::filesystem::path& path);
  /// The file's keys as JSON, from the same key table (reading it as YAML gives this config).
  std::string toJson() const;
};

}  // namespace fvp::host::map
