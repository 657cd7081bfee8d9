#include "scene_primitive.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fvp::robot::sim::detail {
namespace {

// Bounds padding: covers rounding when Embree stores them as floats (~1e-7 relative at 1 m).
constexpr double kBoundsPadM = 1e-5;

// The roots of a t^2 + b t + c = 0 in ascending order (numerically stable form); false when
// there are none.
bool solveQuadratic(double a, double b, double c, double& t0, double& t1) {
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0 || a == 0.0) return false;
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  t0 = q / a;
  t1 = q != 0.0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

double firstInRange(double t0, double t1, double t_min, double t_max) {
  if (t0 > t_min && t0 < t_max) return t0;
  if (t1 > t_min && t1 < t_max) return t1;
  return -1.0;
}

double intersectEllipsoid(const Primitive& prim, const Eigen::Vector3d& o_world,
                          const Eigen::Vector3d& d_world, double t_min, double t_max) {
  // In the frame scaled to a unit sphere, the hit parameters are unchanged.
  const Eigen::Vector3d o = (prim.T_local_world * o_world).cwiseQuotient(prim.semi_axes_m);
  const Eigen::Vector3d d = (prim.T_local_world.linear() * d_world).cwiseQuotient(prim.semi_axes_m);
  double t0 = 0.0, t1 = 0.0;
  if (!solveQuadratic(d.squaredNorm(), 2.0 * o.dot(d), o.squaredNorm() - 1.0, t0, t1)) return -1.0;
  return firstInRange(t0, t1, t_min, t_max);
}

// Capsule: Inigo Quilez's ray-capsule intersection (outside rays), front hit only.
double intersectCapsule(const Primitive& prim, const Eigen::Vector3d& ro, const Eigen::Vector3d& rd,
                        double t_min, double t_max) {
  const Eigen::Vector3d ba = prim.b_m - prim.a_m;
  const Eigen::Vector3d oa = ro - prim.a_m;
  const double baba = ba.dot(ba), bard = ba.dot(rd), baoa = ba.dot(oa);
  const double rdoa = rd.dot(oa), oaoa = oa.dot(oa), r = prim.radius_m;
  const double a = baba - bard * bard;
  double b = baba * rdoa - baoa * bard;
  double c = baba * oaoa - baoa * baoa - r * r * baba;
  double h = b * b - a * c;
  if (h < 0.0) return -1.0;
  if (a > 1e-12) {
    const double t = (-b - std::sqrt(h)) / a;
    const double y = baoa + t * bard;
    if (y > 0.0 && y < baba) return (t > t_min && t < t_max) ? t : -1.0;
  }
  // End caps: the sphere at the nearer end of the body's hit.
  const double y = a > 1e-12 ? baoa + ((-b - std::sqrt(h)) / a) * bard : baoa;
  const Eigen::Vector3d oc = y <= 0.0 ? oa : Eigen::Vector3d(ro - prim.b_m);
  b = rd.dot(oc);
  c = oc.dot(oc) - r * r;
  h = b * b - c;
  if (h <= 0.0) return -1.0;
  const double t = -b - std::sqrt(h);
  return (t > t_min && t < t_max) ? t : -1.0;
}

double intersectLeaf(const Primitive& prim, const Eigen::Vector3d& o_world,
                     const Eigen::Vector3d& d_world, double t_min, double t_max) {
  // Surface z = c x^2 over the ellipse (x/a)^2 + (y/b)^2 <= 1, in the leaf frame.
  const Eigen::Vector3d o = prim.T_local_world * o_world;
  const Eigen::Vector3d d = prim.T_local_world.linear() * d_world;
  const double c = prim.curl_per_m;
  const auto inside = [&](double t) {
    if (!(t > t_min && t < t_max)) return false;
    const double x = (o.x() + t * d.x()) / prim.half_length_m;
    const double y = (o.y() + t * d.y()) / prim.half_width_m;
    return x * x + y * y <= 1.0;
  };
  const double qa = c * d.x() * d.x();
  const double qb = 2.0 * c * o.x() * d.x() - d.z();
  const double qc = c * o.x() * o.x() - o.z();
  if (std::abs(qa) < 1e-12) {
    if (qb == 0.0) return -1.0;
    const double t = -qc / qb;
    return inside(t) ? t : -1.0;
  }
  double t0 = 0.0, t1 = 0.0;
  if (!solveQuadratic(qa, qb, qc, t0, t1)) return -1.0;
  if (inside(t0)) return t0;
  if (inside(t1)) return t1;
  return -1.0;
}

double intersectPlate(const Primitive& prim, const Eigen::Vector3d& o_world,
                      const Eigen::Vector3d& d_world, double t_min, double t_max) {
  const Eigen::Vector3d o = prim.T_local_world * o_world;
  const Eigen::Vector3d d = prim.T_local_world.linear() * d_world;
  if (d.z() == 0.0) return -1.0;
  const double t = -o.z() / d.z();
  if (!(t > t_min && t < t_max)) return -1.0;
  const double h = prim.half_length_m;
  const Eigen::Vector3d p = o + t * d;
  return (std::abs(p.x()) <= h && std::abs(p.y()) <= h) ? t : -1.0;
}

}  // namespace

Primitive makeEllipsoid(const Fruitlet& fruitlet, int object_id) {
  Primitive prim;
  prim.kind = PrimitiveKind::kEllipsoid;
  prim.object_id = object_id;
  prim.source_index = fruitlet.index;
  Eigen::Isometry3d T_world_local = Eigen::Isometry3d::Identity();
  T_world_local.linear() = fruitlet.R_world_fruitlet;
  T_world_local.translation() = fruitlet.center_m;
  prim.T_local_world = T_world_local.inverse();
  prim.semi_axes_m = fruitlet.semiAxes_m();
  return prim;
}

Primitive makeCapsule(const BranchSegment& branch, int source_index, int object_id) {
  Primitive prim;
  prim.kind = PrimitiveKind::kCapsule;
  prim.object_id = object_id;
  prim.source_index = source_index;
  prim.a_m = branch.start_m;
  prim.b_m = branch.end_m;
  prim.radius_m = branch.radius_m;
  return prim;
}

Primitive makeLeaf(const Leaf& leaf, int object_id) {
  Primitive prim;
  prim.kind = PrimitiveKind::kLeaf;
  prim.object_id = object_id;
  prim.source_index = leaf.index;
  prim.T_local_world = leaf.T_world_leaf.inverse();
  prim.half_length_m = leaf.half_length_m;
  prim.half_width_m = leaf.half_width_m;
  prim.curl_per_m = leaf.curl_per_m;
  return prim;
}

Primitive makePlate(const AprilTagPlacement& tag, int object_id) {
  Primitive prim;
  prim.kind = PrimitiveKind::kPlate;
  prim.object_id = object_id;
  prim.T_local_world = tag.T_world_tag.inverse();
  prim.half_length_m = 0.5 * tag.plate_size_m;
  prim.half_width_m = prim.half_length_m;
  return prim;
}

std::array<Eigen::Vector3d, 2> bounds(const Primitive& prim) {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  const Eigen::Isometry3d T_world_local = prim.T_local_world.inverse();
  switch (prim.kind) {
    case PrimitiveKind::kEllipsoid: {
      // Exact AABB of a rotated ellipsoid: extent_i = |row_i(R * diag(s))|.
      const Eigen::Matrix3d M = T_world_local.linear() * prim.semi_axes_m.asDiagonal();
      const Eigen::Vector3d extent = M.rowwise().norm();
      lo = T_world_local.translation() - extent;
      hi = T_world_local.translation() + extent;
      break;
    }
    case PrimitiveKind::kCapsule:
      lo = prim.a_m.cwiseMin(prim.b_m) - Eigen::Vector3d::Constant(prim.radius_m);
      hi = prim.a_m.cwiseMax(prim.b_m) + Eigen::Vector3d::Constant(prim.radius_m);
      break;
    case PrimitiveKind::kLeaf:
    case PrimitiveKind::kPlate: {
      const double sag = prim.curl_per_m * prim.half_length_m * prim.half_length_m;
      lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
      hi = -lo;
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d p_local((corner & 1) ? prim.half_length_m : -prim.half_length_m,
                                      (corner & 2) ? prim.half_width_m : -prim.half_width_m,
                                      (corner & 4) ? std::max(0.0, sag) : std::min(0.0, sag));
        const Eigen::Vector3d p = T_world_local * p_local;
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
      break;
    }
  }
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(kBoundsPadM);
  return {lo - pad, hi + pad};
}

double intersect(const Primitive& prim, const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& dir_unit, double t_min, double t_max) {
  switch (prim.kind) {
    case PrimitiveKind::kEllipsoid:
      return intersectEllipsoid(prim, origin, dir_unit, t_min, t_max);
    case PrimitiveKind::kCapsule:
      return intersectCapsule(prim, origin, dir_unit, t_min, t_max);
    case PrimitiveKind::kLeaf:
      return intersectLeaf(prim, origin, dir_unit, t_min, t_max);
    case PrimitiveKind::kPlate:
      return intersectPlate(prim, origin, dir_unit, t_min, t_max);
  }
  return -1.0;
}

SurfacePoint surfaceAt(const Primitive& prim, const Eigen::Vector3d& p_world) {
  const Eigen::Vector3d p_local = prim.T_local_world * p_world;
  const Eigen::Matrix3d R_world_local = prim.T_local_world.linear().transpose();
  Eigen::Vector3d n_local = Eigen::Vector3d::UnitZ();
  switch (prim.kind) {
    case PrimitiveKind::kEllipsoid:
      n_local = p_local.cwiseQuotient(prim.semi_axes_m.cwiseProduct(prim.semi_axes_m));
      break;
    case PrimitiveKind::kCapsule: {
      const Eigen::Vector3d ba = prim.b_m - prim.a_m;
      const Eigen::Vector3d pa = p_world - prim.a_m;
      const double h = std::clamp(pa.dot(ba) / ba.squaredNorm(), 0.0, 1.0);
      return {(pa - h * ba).normalized(), p_local};
    }
    case PrimitiveKind::kLeaf:
      n_local = Eigen::Vector3d(-2.0 * prim.curl_per_m * p_local.x(), 0.0, 1.0);
      break;
    case PrimitiveKind::kPlate:
      n_local = Eigen::Vector3d::UnitZ();
      break;
  }
  return {(R_world_local * n_local).normalized(), p_local};
}

}  // namespace fvp::robot::sim::detail
