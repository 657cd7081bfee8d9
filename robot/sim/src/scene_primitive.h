// The renderer's analytic primitives: one world object each (fruitlet ellipsoid, bark
// capsule, curled elliptical leaf, tag plate), with an exact ray intersection in double
// precision, its bounds and its surface frame at a hit.
#pragma once

#include <Eigen/Geometry>
#include <array>

#include "fvp/robot/sim/world.h"

namespace fvp::robot::sim::detail {

enum class PrimitiveKind { kEllipsoid, kCapsule, kLeaf, kPlate };

struct Primitive {
  PrimitiveKind kind = PrimitiveKind::kEllipsoid;
  int object_id = 0;
  int source_index = 0;  ///< index into the world's fruitlets / leaves / branches
  /// Local frame of the primitive: ellipsoid/leaf/plate frame (identity for capsules).
  Eigen::Isometry3d T_local_world = Eigen::Isometry3d::Identity();
  Eigen::Vector3d semi_axes_m = Eigen::Vector3d::Ones();                         ///< ellipsoid
  Eigen::Vector3d a_m = Eigen::Vector3d::Zero(), b_m = Eigen::Vector3d::Zero();  ///< capsule
  double radius_m = 0.0;                                                         ///< capsule
  double half_length_m = 0.0, half_width_m = 0.0;  ///< leaf half axes; plate half edge
  double curl_per_m = 0.0;                         ///< leaf
};

Primitive makeEllipsoid(const Fruitlet& fruitlet, int object_id);
Primitive makeCapsule(const BranchSegment& branch, int source_index, int object_id);
Primitive makeLeaf(const Leaf& leaf, int object_id);
Primitive makePlate(const AprilTagPlacement& tag, int object_id);

/// Axis-aligned world bounds (lower, upper), slightly padded for float conversion.
std::array<Eigen::Vector3d, 2> bounds(const Primitive& prim);

/// Smallest ray parameter t in (t_min, t_max) where origin + t * dir_unit hits the surface,
/// or a negative value for no hit. dir_unit must be unit length.
double intersect(const Primitive& prim, const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& dir_unit, double t_min, double t_max);

/// Unit world normal (not oriented to the viewer) at a surface point, and the point in the
/// primitive's local frame (texture coordinates).
struct SurfacePoint {
  Eigen::Vector3d normal_world;
  Eigen::Vector3d p_local;
};
SurfacePoint surfaceAt(const Primitive& prim, const Eigen::Vector3d& p_world);

}  // namespace fvp::robot::sim::detail
