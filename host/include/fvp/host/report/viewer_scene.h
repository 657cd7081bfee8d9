// The scene of a trial's or a capture set's 3-D viewer (docs/viewer.md): the occupied fine
// voxels, the TSDF mesh, the detections and ground truth, the Cluster Regions, the tags, the
// cameras and the planner's chosen viewpoints, as the JSON the page draws. World frame,
// metres; camera frames are OpenCV's (z forward).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fvp/host/core/cluster_region.h"
#include "fvp/host/core/stereo_intrinsics.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/tsdf/marching_cubes.h"

namespace fvp::host::report {

/// [x, y, z] and a pose's {"position_m", "quaternion_wxyz"} (R_world_frame as [w, x, y, z]).
nlohmann::json vec3Json(const Eigen::Vector3d& v);
nlohmann::json poseJson(const Eigen::Isometry3d& T_world_frame);
/// A detection's label in the viewer, the overlays and the report: "D<k>" for the k-th kept
/// detection of a sizing, "X<k>" for the k-th the support rule dropped, prefixed "C<c>." in
/// cluster c of a tree.
std::string detectionLabel(bool kept, std::size_t index, std::optional<int> cluster);
/// A ground-truth fruitlet's label: "F<k>" for the k-th fruitlet of a scoring, "C<c>.F<k>"
/// in cluster c of a tree.
std::string fruitletLabel(std::size_t index, std::optional<int> cluster);
/// Standard base64 (RFC 4648, padded) of a byte buffer.
std::string base64(const void* data, std::size_t bytes);

class ViewerScene {
 public:
  ViewerScene(std::string title, std::string subtitle);

  void setSubtitle(std::string subtitle) { subtitle_ = std::move(subtitle); }
  void setIntrinsics(const StereoIntrinsics& intrinsics);
  /// The map's occupied fine voxels, each flagged when the map holds it as ROI; merged with
  /// those of earlier calls (clusters of a tree), which must share the voxel size.
  void addFineVoxels(const map::MapEngine& map);
  /// Merged with earlier meshes.
  void addMesh(const tsdf::TriangleMesh& mesh);
  void addClusterRegion(const ClusterRegion& region, std::optional<int> cluster);
  void addTag(const Eigen::Isometry3d& T_world_tag, double size_m, int tag_id,
              std::optional<int> cluster);
  /// One captured view; extra's fields (sim_time_s, tag_detected, image, ...) are kept.
  void addCamera(int view, const Eigen::Isometry3d& T_world_camera, nlohmann::json extra = {});
  void addChosenCandidate(int iteration, const Eigen::Isometry3d& T_world_camera, double utility,
                          bool reached, std::optional<int> cluster);
  /// The detections of a sizing ("sized_fruitlets" kept, "unsupported_detections" dropped)
  /// and, when scored, the ground truth ("fruitlets", each naming its detection), as
  /// result.json and fruitlets.json hold them. per_image views are shifted by view_offset
  /// (a tree's cluster numbers its views from its own first).
  void addSizing(const nlohmann::json& sizing, int view_offset, std::optional<int> cluster);

  /// A fruitlet followed over a season (the season viewer): where it is (or was last seen, if
  /// gone), its last size, its growth rate (NaN: none) and its predicted fate ("persists",
  /// "abscises", "gone", "unknown", "unconfirmed"), which the page colours it by.
  void addSeasonFruitlet(const Eigen::Vector3d& center_m, double size_mm, const std::string& label,
                         const std::string& fate, double growth_mm_per_day,
                         std::optional<int> cluster);
  std::size_t voxelCount() const { return voxels_.size(); }
  std::size_t detectionCount() const { return detections_.size(); }
  /// The scene JSON (format "fvp-viewer-scene", version 1).
  nlohmann::json toJson() const;

 private:
  std::string title_, subtitle_;
  std::optional<StereoIntrinsics> intrinsics_;
  double voxel_size_m_ = 0.0;
  std::vector<std::array<std::int64_t, 3>> voxels_;  ///< world lattice indices
  std::vector<std::uint8_t> voxel_roi_;
  std::vector<float> mesh_vertices_m_;
  std::vector<std::uint32_t> mesh_triangles_;
  nlohmann::json detections_ = nlohmann::json::array(), truth_ = nlohmann::json::array(),
                 regions_ = nlohmann::json::array(), tags_ = nlohmann::json::array(),
                 cameras_ = nlohmann::json::array(), candidates_ = nlohmann::json::array();
};

}  // namespace fvp::host::report
