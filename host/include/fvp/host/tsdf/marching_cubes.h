// Marching cubes (Lorensen and Cline 1987) over a signed distance sampled at voxel centres:
// the TSDF's zero level set as an indexed triangle mesh, for people to look at (`mesh.ply`).
// Sizing reads the TSDF's surface points, not this mesh.
//
// The case table is derived at start-up rather than typed in: on each cube face the edges
// with a sign change are joined pairwise, ambiguous faces (diagonal corners inside) keep the
// inside corners apart, and the joins chain into the cycles that are triangulated. The face
// rule depends on the face's four corners only, so two cubes sharing a face cut it the same
// way and the mesh has no cracks. Inside is negative distance (behind the surface).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace fvp::host::tsdf {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices_m;
  /// Counter-clockwise seen from outside (positive distance): normals point out.
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

class MarchingCubes {
 public:
  /// A cube's corners: corner i is at offset (i & 1, (i >> 1) & 1, (i >> 2) & 1).
  /// Edge a * 4 + j runs along axis a from the j-th corner (in increasing order) whose bit a
  /// is 0.
  static constexpr int kCorners = 8;
  static constexpr int kEdges = 12;
  static std::array<int, 2> edgeCorners(int edge);

  /// The cycles of edge indices cut by the surface for a corner configuration (bit i set:
  /// corner i inside). Empty for 0 and 255.
  static const std::vector<std::vector<int>>& cycles(int configuration);

  /// Distance at a voxel index; false where the voxel is unobserved (cubes touching it are
  /// skipped).
  using Sampler = std::function<bool(const std::array<int, 3>& index, float& distance)>;

  /// Meshes the cubes whose lowest corner is one of cube_origins (each at most once):
  /// vertices are shared between cubes, interpolated linearly along cube edges. Voxel index
  /// g sits at origin_m + g * voxel_size_m. Indices must be non-negative and below 2^20.
  static TriangleMesh extract(const std::vector<std::array<int, 3>>& cube_origins,
                              const Sampler& sample, const Eigen::Vector3d& origin_m,
                              double voxel_size_m);
};

}  // namespace fvp::host::tsdf
