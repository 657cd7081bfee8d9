#include "fvp/host/planner/info_gain_evaluator.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "fvp/accel/backend.h"
#include "fvp/accel/kernels.h"
#include "fvp/accel/sequence.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/map/occupied_voxel_scene.h"

namespace fvp::host::planner {

GainMode parseGainMode(std::string_view name) {
  if (name == "single_ray") return GainMode::kSingleRay;
  if (name == "frustum") return GainMode::kFrustum;
  throw std::invalid_argument("gain mode: expected single_ray or frustum, got '" +
                              std::string(name) + "'");
}
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

InfoGainEvaluator::InfoGainEvaluator(const InfoGainConfig& config, accel::Backend* backend)
    : config_(config), backend_(backend) {
  config_.validate();
}

InfoGainEvaluator::~InfoGainEvaluator() = default;
InfoGainEvaluator::InfoGainEvaluator(InfoGainEvaluator&&) noexcept = default;
InfoGainEvaluator& InfoGainEvaluator::operator=(InfoGainEvaluator&&) noexcept = default;

const char* InfoGainEvaluator::walkDevice() const {
  return backend_ ? accel::toString(backend_->kind()).data() : "host";
}

namespace {

bool sameGrid(const map::GridGeometry& a, const map::GridGeometry& b) {
  return a.voxel_size_m == b.voxel_size_m && a.first_voxel == b.first_voxel && a.dims == b.dims;
}

// Ranges closer than this are sent as one: a transfer (an enqueued write, a copy region)
// costs about what copying a few KB does, and the bytes between two ranges of the host
// image equal what the device holds anyway.
constexpr std::size_t kMergeGapBytes = 4096;

/// The byte ranges of a dense snapshot (x fastest, voxels_per_word voxels to a 32-bit word)
/// that the given bricks occupy: per brick and z plane, its first row's first word to its
/// last row's last; sorted and merged.
std::vector<accel::ByteRange> brickRanges(const map::GridGeometry& grid,
                                          const std::array<int, 3>& bricks_per_axis,
                                          const std::vector<int>& bricks, int voxels_per_word) {
  constexpr int e = map::BrickChangeLog::kBrickEdge;
  const std::size_t dx = grid.dims[0], dy = grid.dims[1];
  std::vector<accel::ByteRange> ranges;
  ranges.reserve(bricks.size() * e);
  for (int id : bricks) {
    const int bx = id % bricks_per_axis[0], by = (id / bricks_per_axis[0]) % bricks_per_axis[1],
              bz = id / (bricks_per_axis[0] * bricks_per_axis[1]);
    for (int z = bz * e; z < std::min(bz * e + e, grid.dims[2]); ++z) {
      const std::size_t first = bx * e + dx * (by * e + dy * z);
      const std::size_t last = std::min(bx * e + e, grid.dims[0]) - 1 +
                               dx * (std::min(by * e + e, grid.dims[1]) - 1 + dy * z);
      const std::size_t w0 = first / voxels_per_word, w1 = last / voxels_per_word + 1;
      ranges.push_back({w0 * sizeof(std::uint32_t), (w1 - w0) * sizeof(std::uint32_t)});
    }
  }
  std::sort(ranges.begin(), ranges.end(),
            [](const auto& a, const auto& b) { return a.offset_bytes < b.offset_bytes; });
  std::vector<accel::ByteRange> merged;
  for (const accel::ByteRange& r : ranges) {
    if (!merged.empty() &&
        r.offset_bytes <= merged.back().offset_bytes + merged.back().size_bytes + kMergeGapBytes) {
      const std::size_t end = std::max(merged.back().offset_bytes + merged.back().size_bytes,
                                       r.offset_bytes + r.size_bytes);
      merged.back().size_bytes = end - merged.back().offset_bytes;
    } else {
      merged.push_back(r);
    }
  }
  return merged;
}

/// Bricks per axis of a grid (brick_change_log.h).
std::array<int, 3> bricksPerAxis(const map::GridGeometry& grid) {
  constexpr int e = map::BrickChangeLog::kBrickEdge;
  return {(grid.dims[0] + e - 1) / e, (grid.dims[1] + e - 1) / e, (grid.dims[2] + e - 1) / e};
}

/// Calls f(index) for every voxel of a brick (brick_change_log.h id) of the grid.
template <typename F>
void forVoxelsOfBrick(const map::GridGeometry& grid, const std::array<int, 3>& bricks_per_axis,
                      int id, F&& f) {
  constexpr int e = map::BrickChangeLog::kBrickEdge;
  const int bx = id % bricks_per_axis[0], by = (id / bricks_per_axis[0]) % bricks_per_axis[1],
            bz = id / (bricks_per_axis[0] * bricks_per_axis[1]);
  for (int z = bz * e; z < std::min(bz * e + e, grid.dims[2]); ++z)
    for (int y = by * e; y < std::min(by * e + e, grid.dims[1]); ++y)
      for (int x = bx * e; x < std::min(bx * e + e, grid.dims[0]); ++x)
        f(std::array<int, 3>{x, y, z});
}

}  // namespace

double InfoGainEvaluator::refresh(map::MapEngine& map) {
  const auto start = std::chrono::steady_clock::now();
  map.updateRoiDistance(config_.max_d_m);
  const auto distance_done = std::chrono::steady_clock::now();
  const map::BrickChanges fine = map.changesSince(map::MapLevel::kFine, fine_cursor_);
  const map::BrickChanges coarse = map.changesSince(map::MapLevel::kCoarse, coarse_cursor_);
  // The cursors' epochs already tell another map or region; the grids are checked too,
  // since everything below indexes them.
  const bool same = ready_ && !fine.all && !coarse.all &&
                    sameGrid(fine_, map.gridGeometry(map::MapLevel::kFine)) &&
                    sameGrid(coarse_, map.gridGeometry(map::MapLevel::kCoarse)) &&
                    region_center_m_ == map.region().center_m() &&
                    region_radius_m_ == map.region().radius_m();
  last_refresh_ = SnapshotRefreshStats{};
  if (same) {
    updateBricks(map, fine.bricks, coarse.bricks);
  } else {
    rebuild(map);
  }
  coarse_scene_ = config_.embree_cull ? &map.occupiedScene(map::MapLevel::kCoarse) : nullptr;
  fine_cursor_ = fine.now;
  coarse_cursor_ = coarse.now;
  ready_ = true;
  snapshot_scans_ = map.scanCount();
  const auto end = std::chrono::steady_clock::now();
  last_refresh_.distance_s = std::chrono::duration<double>(distance_done - start).count();
  last_refresh_.snapshot_s = std::chrono::duration<double>(end - distance_done).count();
  return std::chrono::duration<double>(end - start).count();
}

std::uint16_t InfoGainEvaluator::computeFineCode(const map::MapEngine& map,
                                                 const fvp_region& region,
                                                 const std::array<int, 3>& index) const {
  if (!fvp_region_contains(&region, index[0], index[1], index[2])) return 0;
  const map::VoxelState s = map.fineState(fine_.voxelCenter_m(index));
  std::uint16_t code = kInRegion;
  if (s.occupancy == map::VoxelClass::kOccupied) {
    code |= kOccupied;
  } else if (s.occupancy == map::VoxelClass::kUnknown) {
    const double w = roiProximityWeight(map.roiDistance_m(index), config_.max_d_m);
    code |= static_cast<std::uint16_t>(std::lround(w * kWeightScale));
  }
  return code;
}

void InfoGainEvaluator::rebuild(const map::MapEngine& map) {
  fine_ = map.gridGeometry(map::MapLevel::kFine);
  coarse_ = map.gridGeometry(map::MapLevel::kCoarse);
  region_center_m_ = map.region().center_m();
  region_radius_m_ = map.region().radius_m();

  coarse_words_.assign(accel::gainCoarseWords(coarse_.params()), 0u);
  const auto cstride = [&](const std::array<int, 3>& v) {
    return v[0] + std::size_t(coarse_.dims[0]) * (v[1] + std::size_t(coarse_.dims[1]) * v[2]);
  };
  for (const auto& v : map.occupiedVoxels(map::MapLevel::kCoarse)) {
    const std::size_t i = cstride(v);
    coarse_words_[i >> 2] |= 1u << ((i & 3) * 8);
  }

  // Codes per voxel first (z slices in parallel: the engines' const reads are thread-safe),
  // then packed two to a word.
  const fvp_region region = map::regionInGrid(fine_, map.region());
  std::vector<std::uint16_t> codes(static_cast<std::size_t>(fine_.voxelCount()), 0);
#pragma omp parallel for schedule(dynamic, 1)
  for (int z = 0; z < fine_.dims[2]; ++z)
    for (int y = 0; y < fine_.dims[1]; ++y)
      for (int x = 0; x < fine_.dims[0]; ++x)
        codes[x + std::size_t(fine_.dims[0]) * (y + std::size_t(fine_.dims[1]) * z)] =
            computeFineCode(map, region, {x, y, z});
  fine_words_.assign(accel::gainFineWords(fine_.params()), 0u);
  for (std::size_t i = 0; i < codes.size(); ++i)
    fine_words_[i >> 1] |= std::uint32_t{codes[i]} << ((i & 1) * 16);
  if (backend_) {
    fine_device_ = backend_->createBufferFrom(fine_words_);
    coarse_device_ = backend_->createBufferFrom(coarse_words_);
    last_refresh_.upload_bytes = snapshotBytes();
    last_refresh_.upload_ranges = 2;
  }
  last_refresh_.full = true;
  const auto bricks = [](const map::GridGeometry& g) {
    const std::array<int, 3> n = bricksPerAxis(g);
    return std::size_t(n[0]) * n[1] * n[2];
  };
  last_refresh_.fine_bricks = bricks(fine_);
  last_refresh_.coarse_bricks = bricks(coarse_);
}

void InfoGainEvaluator::updateBricks(const map::MapEngine& map, const std::vector<int>& fine_bricks,
                                     const std::vector<int>& coarse_bricks) {
  const std::array<int, 3> fine_per_axis = bricksPerAxis(fine_);
  const std::array<int, 3> coarse_per_axis = bricksPerAxis(coarse_);
  const fvp_region region = map::regionInGrid(fine_, map.region());
  // With x dimensions of whole bricks a brick's rows start at multiples of 8 voxels, so no
  // two bricks share a word: bricks are rewritten in parallel without races (else serially).
  const bool fine_parallel = fine_.dims[0] % map::BrickChangeLog::kBrickEdge == 0;
  const bool coarse_parallel = coarse_.dims[0] % map::BrickChangeLog::kBrickEdge == 0;
#pragma omp parallel for schedule(dynamic, 4) if (fine_parallel)
  for (std::ptrdiff_t k = 0; k < std::ptrdiff_t(fine_bricks.size()); ++k)
    forVoxelsOfBrick(fine_, fine_per_axis, fine_bricks[k], [&](const std::array<int, 3>& v) {
      const std::size_t i =
          v[0] + std::size_t(fine_.dims[0]) * (v[1] + std::size_t(fine_.dims[1]) * v[2]);
      const unsigned shift = (i & 1) * 16;
      std::uint32_t& word = fine_words_[i >> 1];
      word = (word & ~(0xFFFFu << shift)) | std::uint32_t{computeFineCode(map, region, v)} << shift;
    });
#pragma omp parallel for schedule(dynamic, 4) if (coarse_parallel)
  for (std::ptrdiff_t k = 0; k < std::ptrdiff_t(coarse_bricks.size()); ++k)
    forVoxelsOfBrick(coarse_, coarse_per_axis, coarse_bricks[k], [&](const std::array<int, 3>& v) {
      const std::size_t i =
          v[0] + std::size_t(coarse_.dims[0]) * (v[1] + std::size_t(coarse_.dims[1]) * v[2]);
      const unsigned shift = (i & 3) * 8;
      const bool occupied = map.coarseClass(coarse_.voxelCenter_m(v)) == map::VoxelClass::kOccupied;
      std::uint32_t& word = coarse_words_[i >> 2];
      word = (word & ~(0xFFu << shift)) | std::uint32_t{occupied} << shift;
    });
  last_refresh_.full = false;
  last_refresh_.fine_bricks = fine_bricks.size();
  last_refresh_.coarse_bricks = coarse_bricks.size();
  if (!backend_) return;
  const auto send = [&](accel::DeviceBuffer& device, const std::vector<std::uint32_t>& words,
                        const std::vector<accel::ByteRange>& ranges) {
    backend_->uploadRanges(device, words.data(), ranges);
    for (const accel::ByteRange& r : ranges) last_refresh_.upload_bytes += r.size_bytes;
    last_refresh_.upload_ranges += ranges.size();
  };
  send(*fine_device_, fine_words_, brickRanges(fine_, fine_per_axis, fine_bricks, 2));
  send(*coarse_device_, coarse_words_, brickRanges(coarse_, coarse_per_axis, coarse_bricks, 4));
}

std::vector<std::uint32_t> InfoGainEvaluator::deviceFineWords() const {
  return backend_ && fine_device_ ? backend_->downloadAll<std::uint32_t>(*fine_device_)
                                  : std::vector<std::uint32_t>{};
}

std::vector<std::uint32_t> InfoGainEvaluator::deviceCoarseWords() const {
  return backend_ && coarse_device_ ? backend_->downloadAll<std::uint32_t>(*coarse_device_)
                                    : std::vector<std::uint32_t>{};
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
      r.occluded = coarseOccupied(i);
      return !r.occluded;
    });
  };
  const auto walkFine = [&](double t0, double t1) {
    walkSegment(fine_, from_m + t0 * d, from_m + t1 * d, &r.voxel_steps, [&](std::size_t i) {
      const std::uint16_t code = fineCode(i);
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

double InfoGainEvaluator::visibleFraction(const Eigen::Vector3d& camera_m,
                                          const Eigen::Vector3d& center_m, double radius_m) const {
  const Eigen::Vector3d to_camera = camera_m - center_m;
  const double distance_m = to_camera.norm();
  if (!(distance_m > radius_m)) return 0.0;
  const Eigen::Vector3d n = to_camera / distance_m;
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  const double pullback_m = 2.0 * fine_.voxel_size_m;
  int rays = 0, seen = 0;
  const auto cast = [&](double along_u_m, double along_v_m) {
    const Eigen::Vector3d offset = along_u_m * u + along_v_m * v;
    const Eigen::Vector3d surface =
        center_m + offset +
        std::sqrt(std::max(0.0, radius_m * radius_m - offset.squaredNorm())) * n;
    const Eigen::Vector3d end = surface + pullback_m * (camera_m - surface).normalized();
    ++rays;
    seen += !census(camera_m, end).occluded;
  };
  // The centre and two rings (at half and 85 % of the radius): each ray stands for about the
  // same area of the disc.
  cast(0.0, 0.0);
  for (const auto& [ring, count] : {std::pair{0.5, 6}, std::pair{0.85, 12}})
    for (int k = 0; k < count; ++k) {
      const double a = 2.0 * M_PI * k / count;
      cast(ring * radius_m * std::cos(a), ring * radius_m * std::sin(a));
    }
  return static_cast<double>(seen) / rays;
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
        if (coarseOccupied(g[0] + std::size_t(coarse_.dims[0]) *
                                      (g[1] + std::size_t(coarse_.dims[1]) * g[2])))
          return true;
      }
  return false;
}

std::size_t InfoGainEvaluator::snapshotBytes() const {
  return (fine_words_.size() + coarse_words_.size()) * sizeof(std::uint32_t);
}

namespace {

// A ray split at the region sphere (kernels/fvp_info_gain.h); false when it never enters.
bool makeSegment(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& end_m,
                 const Eigen::Vector3d& center_m, double radius_m, accel::GainSegment* s) {
  const double t_enter = sphereEntry(origin_m, end_m, center_m, radius_m);
  if (t_enter < 0.0) return false;  // never enters the region: nothing to gain
  toFloat3(origin_m, s->origin_m);
  toFloat3(origin_m + t_enter * (end_m - origin_m), s->entry_m);
  toFloat3(end_m, s->end_m);
  s->origin_m[3] = t_enter > 0.0 ? 1.0f : 0.0f;
  s->entry_m[3] = s->end_m[3] = 0.0f;
  return true;
}

GainResult toGain(const accel::GainResultRaw& raw) {
  GainResult r;
  r.region_voxels = raw.region_voxels;
  r.voxel_steps = raw.voxel_steps;
  r.blocked = raw.blocked != 0;
  if (r.region_voxels > 0)
    r.ig = double(raw.weight_sum) / InfoGainEvaluator::kWeightScale / r.region_voxels;
  return r;
}

// Segments per kernel dispatch: bounds the staging memory (48 + 16 bytes per segment).
constexpr std::size_t kSegmentsPerDispatch = std::size_t{1} << 20;

}  // namespace

GainResult InfoGainEvaluator::evaluateRay(const Eigen::Vector3d& origin_m,
                                          const Eigen::Vector3d& end_m) const {
  accel::GainSegment s;
  if (!makeSegment(origin_m, end_m, region_center_m_, region_radius_m_, &s)) return {};
  const accel::GainParams params{fine_.params(), coarse_.params(), 1u};
  return toGain(fvp_gain_walk(&params, s.origin_m, s.entry_m, s.end_m, s.origin_m[3] != 0.0f,
                              fine_words_.data(), coarse_words_.data()));
}

void InfoGainEvaluator::walk(std::span<const accel::GainSegment> segments,
                             accel::GainResultRaw* results) const {
  if (segments.empty()) return;
  if (backend_) {
    // Segment and result buffers grow and are kept: planning calls evaluate() thousands of
    // times per trial, and a device allocation each time costs more than the walks on a GPU.
    const std::size_t batch = std::min(kSegmentsPerDispatch, segments.size());
    if (!segment_device_ || segment_device_->sizeBytes() < batch * sizeof(accel::GainSegment)) {
      segment_device_ = backend_->createBuffer(batch * sizeof(accel::GainSegment));
      result_device_ = backend_->createBuffer(batch * sizeof(accel::GainResultRaw));
    }
    // Each batch's upload, walk and download in one submission.
    accel::Sequence seq(*backend_);
    for (std::size_t first = 0; first < segments.size(); first += kSegmentsPerDispatch) {
      const std::size_t n = std::min(kSegmentsPerDispatch, segments.size() - first);
      const accel::GainParams params{fine_.params(), coarse_.params(), std::uint32_t(n)};
      seq.upload(*segment_device_, segments.data() + first, n * sizeof(accel::GainSegment))
          .run(accel::kernels::infoGain(), params,
               {segment_device_.get(), fine_device_.get(), coarse_device_.get(),
                result_device_.get()})
          .download(*result_device_, results + first, n * sizeof(accel::GainResultRaw))
          .eval();
    }
    return;
  }
  const accel::GainParams params{fine_.params(), coarse_.params(), std::uint32_t(segments.size())};
#pragma omp parallel for schedule(dynamic, 64)
  for (std::ptrdiff_t i = 0; i < std::ptrdiff_t(segments.size()); ++i)
    results[i] =
        fvp_gain_walk(&params, segments[i].origin_m, segments[i].entry_m, segments[i].end_m,
                      segments[i].origin_m[3] != 0.0f, fine_words_.data(), coarse_words_.data());
}

std::vector<GainResult> InfoGainEvaluator::evaluate(std::span<const ViewQuery> queries,
                                                    EvaluateStats* stats) const {
  if (!ready_) throw std::logic_error("InfoGainEvaluator::evaluate before refresh()");
  const bool frustum = config_.mode == GainMode::kFrustum;
  const int nx = frustum ? config_.frustum_rays_x : 1, ny = frustum ? config_.frustum_rays_y : 1;
  const std::size_t rays_per_query = std::size_t(nx) * ny;
  const double tx = std::tan(0.5 * config_.fov_x_rad), ty = std::tan(0.5 * config_.fov_y_rad);

  // Every ray of every query; those that never enter the region get slot -1 (gain 0).
  std::vector<accel::GainSegment> segments;
  segments.reserve(queries.size() * rays_per_query);
  std::vector<std::int64_t> slot(queries.size() * rays_per_query, -1);
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const Eigen::Isometry3d& T = queries[q].T_world_camera;
    const Eigen::Vector3d c = T.translation();
    // Frustum: rays end on the plane through the target parallel to the image.
    const double depth = frustum ? (T.inverse() * queries[q].target_m).z() : 1.0;
    if (!(depth > 0.0)) continue;
    for (int v = 0; v < ny; ++v)
      for (int u = 0; u < nx; ++u) {
        const Eigen::Vector3d end =
            frustum ? Eigen::Vector3d(
                          T * (depth * Eigen::Vector3d(((u + 0.5) / nx * 2.0 - 1.0) * tx,
                                                       ((v + 0.5) / ny * 2.0 - 1.0) * ty, 1.0)))
                    : queries[q].target_m;
        accel::GainSegment s;
        if (!makeSegment(c, end, region_center_m_, region_radius_m_, &s)) continue;
        slot[q * rays_per_query + std::size_t(v) * nx + u] = std::int64_t(segments.size());
        segments.push_back(s);
      }
  }

  EvaluateStats st;
  st.rays = segments.size();
  std::vector<accel::GainResultRaw> walked(segments.size(), accel::GainResultRaw{0u, 0u, 0u, 0u});
  if (coarse_scene_) {
    // Embree first: the coarse part of each ray that starts outside the region.
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<accel::Ray> coarse_parts;
    std::vector<std::size_t> coarse_of;
    for (std::size_t i = 0; i < segments.size(); ++i)
      if (segments[i].origin_m[3] != 0.0f) {
        const auto& s = segments[i];
        coarse_parts.push_back(accel::makeRay({s.origin_m[0], s.origin_m[1], s.origin_m[2]},
                                              {s.entry_m[0], s.entry_m[1], s.entry_m[2]}));
        coarse_of.push_back(i);
      }
    const std::vector<std::uint8_t> blocked = coarse_scene_->occludedBatch(coarse_parts);
    std::vector<std::uint8_t> culled(segments.size(), 0);
    for (std::size_t k = 0; k < blocked.size(); ++k)
      if (blocked[k]) {
        culled[coarse_of[k]] = 1;
        walked[coarse_of[k]].blocked = 1u;
        ++st.culled;
      }
    std::vector<accel::GainSegment> kept;
    std::vector<std::size_t> kept_of;
    kept.reserve(segments.size() - st.culled);
    for (std::size_t i = 0; i < segments.size(); ++i)
      if (!culled[i]) {
        kept.push_back(segments[i]);
        kept_of.push_back(i);
      }
    st.cull_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto t1 = std::chrono::steady_clock::now();
    std::vector<accel::GainResultRaw> kept_walked(kept.size());
    walk(kept, kept_walked.data());
    for (std::size_t k = 0; k < kept.size(); ++k) walked[kept_of[k]] = kept_walked[k];
    st.walked = kept.size();
    st.walk_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  } else {
    const auto t1 = std::chrono::steady_clock::now();
    walk(segments, walked.data());
    st.walked = segments.size();
    st.walk_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  }
  if (stats) *stats = st;

  std::vector<GainResult> out(queries.size());
  for (std::size_t q = 0; q < queries.size(); ++q) {
    if (!frustum) {
      if (slot[q] >= 0) out[q] = toGain(walked[slot[q]]);
      continue;
    }
    GainResult sum;
    double ig_sum = 0.0;
    for (std::size_t k = 0; k < rays_per_query; ++k) {
      const std::int64_t i = slot[q * rays_per_query + k];
      if (i < 0) continue;
      const GainResult ray = toGain(walked[i]);
      ig_sum += ray.ig;
      sum.region_voxels += ray.region_voxels;
      sum.voxel_steps += ray.voxel_steps;
    }
    sum.ig = ig_sum / double(rays_per_query);
    out[q] = sum;
  }
  return out;
}

}  // namespace fvp::host::planner
