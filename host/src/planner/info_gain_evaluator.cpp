#include "fvp/host/planner/info_gain_evaluator.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "fvp/host/map/map_engine.h"

extern "C" {
#include "fvp_dda.h"
}

namespace fvp::host::planner {
namespace {

// Parameter of the first intersection of origin + t (end - origin), t in [0, 1], with the
// sphere; 0 when origin is inside; negative when the segment misses it.
double sphereEntry(const Eigen::Vector3d& o, const Eigen::Vector3d& e, const Eigen::Vector3d& c,
                   double r) {
  const Eigen::Vector3d d = e - o, f = o - c;
  const double a = d.squaredNorm(), b = 2.0 * f.dot(d), cc = f.squaredNorm() - r * r;
  if (cc <= 0.0) return 0.0;
  if (a == 0.0) return -1.0;
  const double disc = b * b - 4.0 * a * cc;
  if (disc < 0.0) return -1.0;
  const double t = (-b - std::sqrt(disc)) / (2.0 * a);
  return (t >= 0.0 && t <= 1.0) ? t : -1.0;
}

void toFloat3(const Eigen::Vector3d& v, float* out) {
  out[0] = static_cast<float>(v.x());
  out[1] = static_cast<float>(v.y());
  out[2] = static_cast<float>(v.z());
}

/// Walks the grid voxels of the segment a -> b with the exact DDA, calling visit(linear
/// index) for each until it returns false or the walk ends (end voxel or grid edge); counts
/// the voxels in *steps.
template <typename Visit>
void walkSegment(const map::GridGeometry& grid, const Eigen::Vector3d& a_m,
                 const Eigen::Vector3d& b_m, std::uint64_t* steps, Visit&& visit) {
  const fvp_grid_params g = grid.params();
  float o[3], e[3];
  toFloat3(a_m, o);
  toFloat3(b_m, e);
  fvp_dda w;
  if (fvp_dda_init(&w, &g, o, e) != 0) return;
  for (;;) {
    ++*steps;
    if (!visit(w.key[0] + std::size_t(g.dim_x) * (w.key[1] + std::size_t(g.dim_y) * w.key[2])))
      return;
    const int axis = fvp_dda_next_axis(&w);
    if (axis < 0) return;
    fvp_dda_advance(&w, axis);
    if (w.key[axis] < 0 || w.key[axis] >= (&g.dim_x)[axis]) return;
  }
}

}  // namespace

void InfoGainConfig::validate() const {
  if (!(max_d_m > 0.0)) throw std::invalid_argument("info gain: max_d_m must be > 0");
  if (frustum_rays_x < 1 || frustum_rays_y < 1 || frustum_rays_x * frustum_rays_y > 4096)
    throw std::invalid_argument("info gain: frustum_rays_x * frustum_rays_y must be 1 to 4096");
  if (!(fov_x_rad > 0.0 && fov_x_rad < 3.0) || !(fov_y_rad > 0.0 && fov_y_rad < 3.0))
    throw std::invalid_argument("info gain: fov_x_rad and fov_y_rad must be in (0, 3) rad");
}

InfoGainEvaluator::InfoGainEvaluator(const InfoGainConfig& config) : config_(config) {
  config_.validate();
}

double InfoGainEvaluator::refresh(map::MapEngine& map) {
  const auto start = std::chrono::steady_clock::now();
  map.updateRoiDistance(config_.max_d_m);
  fine_ = map.gridGeometry(map::MapLevel::kFine);
  coarse_ = map.gridGeometry(map::MapLevel::kCoarse);
  region_center_m_ = map.region().center_m();
  region_radius_m_ = map.region().radius_m();

  coarse_occupied_.assign(static_cast<std::size_t>(coarse_.voxelCount()), 0);
  const auto cstride = [&](const std::array<int, 3>& v) {
    return v[0] + std::size_t(coarse_.dims[0]) * (v[1] + std::size_t(coarse_.dims[1]) * v[2]);
  };
  for (const auto& v : map.occupiedVoxels(map::MapLevel::kCoarse)) coarse_occupied_[cstride(v)] = 1;

  fine_codes_.assign(static_cast<std::size_t>(fine_.voxelCount()), 0);
  const fvp_region region = map::regionInGrid(fine_, map.region());
  for (int z = 0; z < fine_.dims[2]; ++z)
    for (int y = 0; y < fine_.dims[1]; ++y)
      for (int x = 0; x < fine_.dims[0]; ++x) {
        if (!fvp_region_contains(&region, x, y, z)) continue;
        const std::array<int, 3> index{x, y, z};
        const map::VoxelState s = map.fineState(fine_.voxelCenter_m(index));
        std::uint16_t code = kInRegion;
        if (s.occupancy == map::VoxelClass::kOccupied) {
          code |= kOccupied;
        } else if (s.occupancy == map::VoxelClass::kUnknown) {
          const double w = roiProximityWeight(map.roiDistance_m(index), config_.max_d_m);
          code |= static_cast<std::uint16_t>(std::lround(w * kWeightScale));
        }
        fine_codes_[x + std::size_t(fine_.dims[0]) * (y + std::size_t(fine_.dims[1]) * z)] = code;
      }
  ready_ = true;
  snapshot_scans_ = map.scanCount();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

InfoGainEvaluator::RayCensus InfoGainEvaluator::census(const Eigen::Vector3d& from_m,
                                                       const Eigen::Vector3d& to_m) const {
  if (!ready_) throw std::logic_error("InfoGainEvaluator::census before refresh()");
  RayCensus r;
  // The segment's part inside the sphere: [t_in, t_out] within [0, 1], if any.
  const Eigen::Vector3d d = to_m - from_m, f = from_m - region_center_m_;
  const double a = d.squaredNorm(), b = 2.0 * f.dot(d),
               c = f.squaredNorm() - region_radius_m_ * region_radius_m_;
  const double disc = b * b - 4.0 * a * c;
  double t_in = 2.0, t_out = 2.0;
  if (a > 0.0 && disc >= 0.0) {
    t_in = std::max(0.0, (-b - std::sqrt(disc)) / (2.0 * a));
    t_out = std::min(1.0, (-b + std::sqrt(disc)) / (2.0 * a));
    if (t_in > t_out) t_in = t_out = 2.0;
  }
  const auto walkCoarse = [&](double t0, double t1) {
    if (!(t1 > t0)) return;
    walkSegment(coarse_, from_m + t0 * d, from_m + t1 * d, &r.voxel_steps, [&](std::size_t i) {
      r.occluded = coarse_occupied_[i] != 0;
      return !r.occluded;
    });
  };
  const auto walkFine = [&](double t0, double t1) {
    walkSegment(fine_, from_m + t0 * d, from_m + t1 * d, &r.voxel_steps, [&](std::size_t i) {
      const std::uint16_t code = fine_codes_[i];
      if (!(code & kInRegion)) return true;
      if (code & kOccupied) {
        r.occluded = true;
        return false;
      }
      ++r.region_voxels;
      r.unknown_voxels += (code & kWeightMask) != 0;
      return true;
    });
  };
  if (t_in > 1.0) {
    walkCoarse(0.0, 1.0);
    return r;
  }
  walkCoarse(0.0, t_in);
  if (!r.occluded) walkFine(t_in, t_out);
  if (!r.occluded) walkCoarse(t_out, 1.0);
  return r;
}

bool InfoGainEvaluator::occupiedWithin(const Eigen::Vector3d& p_m, double radius_m) const {
  const double vs = coarse_.voxel_size_m;
  const auto lo = coarse_.latticeIndex(p_m - Eigen::Vector3d::Constant(radius_m));
  const auto hi = coarse_.latticeIndex(p_m + Eigen::Vector3d::Constant(radius_m));
  for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
    for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
      for (std::int64_t x = lo[0]; x <= hi[0]; ++x) {
        const std::int64_t g[3] = {x - coarse_.first_voxel[0], y - coarse_.first_voxel[1],
                                   z - coarse_.first_voxel[2]};
        if (g[0] < 0 || g[1] < 0 || g[2] < 0 || g[0] >= coarse_.dims[0] ||
            g[1] >= coarse_.dims[1] || g[2] >= coarse_.dims[2])
          continue;
        const Eigen::Vector3d c((x + 0.5) * vs, (y + 0.5) * vs, (z + 0.5) * vs);
        if ((c - p_m).norm() > radius_m) continue;
        if (coarse_occupied_[g[0] + std::size_t(coarse_.dims[0]) *
                                        (g[1] + std::size_t(coarse_.dims[1]) * g[2])])
          return true;
      }
  return false;
}

std::size_t InfoGainEvaluator::snapshotBytes() const {
  return fine_codes_.size() * sizeof(std::uint16_t) + coarse_occupied_.size();
}

GainResult InfoGainEvaluator::evaluateRay(const Eigen::Vector3d& origin_m,
                                          const Eigen::Vector3d& end_m) const {
  GainResult r;
  const double t_enter = sphereEntry(origin_m, end_m, region_center_m_, region_radius_m_);
  if (t_enter < 0.0) return r;  // never enters the region: nothing to gain
  const Eigen::Vector3d entry_m = origin_m + t_enter * (end_m - origin_m);
  float o[3], e[3];

  // Coarse map up to the region: the first occupied voxel blocks the view.
  if (t_enter > 0.0)
    walkSegment(coarse_, origin_m, entry_m, &r.voxel_steps, [&](std::size_t i) {
      r.blocked = coarse_occupied_[i] != 0;
      return !r.blocked;
    });
  if (r.blocked) return r;

  // Fine map from the region's surface to the end point.
  std::uint64_t weight_sum = 0;
  walkSegment(fine_, entry_m, end_m, &r.voxel_steps, [&](std::size_t i) {
    const std::uint16_t code = fine_codes_[i];
    if (!(code & kInRegion)) return true;
    ++r.region_voxels;
    if (code & kOccupied) return false;
    weight_sum += code & kWeightMask;
    return true;
  });
  if (r.region_voxels > 0) r.ig = double(weight_sum) / kWeightScale / r.region_voxels;
  return r;
}

std::vector<GainResult> InfoGainEvaluator::evaluate(std::span<const ViewQuery> queries) const {
  if (!ready_) throw std::logic_error("InfoGainEvaluator::evaluate before refresh()");
  std::vector<GainResult> out(queries.size());
  const double tx = std::tan(0.5 * config_.fov_x_rad), ty = std::tan(0.5 * config_.fov_y_rad);
  const int nx = config_.frustum_rays_x, ny = config_.frustum_rays_y;
#pragma omp parallel for schedule(dynamic, 16)
  for (std::ptrdiff_t i = 0; i < std::ptrdiff_t(queries.size()); ++i) {
    const ViewQuery& q = queries[i];
    const Eigen::Vector3d c = q.T_world_camera.translation();
    if (config_.mode == GainMode::kSingleRay) {
      out[i] = evaluateRay(c, q.target_m);
      continue;
    }
    // Frustum: rays end on the plane through the target parallel to the image.
    const double depth = (q.T_world_camera.inverse() * q.target_m).z();
    GainResult sum;
    double ig_sum = 0.0;
    if (depth > 0.0) {
      for (int v = 0; v < ny; ++v)
        for (int u = 0; u < nx; ++u) {
          const Eigen::Vector3d dir_camera(((u + 0.5) / nx * 2.0 - 1.0) * tx,
                                           ((v + 0.5) / ny * 2.0 - 1.0) * ty, 1.0);
          const GainResult ray = evaluateRay(c, q.T_world_camera * (depth * dir_camera));
          ig_sum += ray.ig;
          sum.region_voxels += ray.region_voxels;
          sum.voxel_steps += ray.voxel_steps;
        }
    }
    sum.ig = ig_sum / (nx * ny);
    out[i] = sum;
  }
  return out;
}

}  // namespace fvp::host::planner
