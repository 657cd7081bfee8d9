#include "fvp/host/map/octomap_map_engine.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <dynamicEDT3D/dynamicEDTOctomap.h>

#include "fvp/accel/kernel_types.h"  // fvp_edt_distance_vox: the grid engine's conversion
#include "fvp/host/map/octomap_io.h"
#include "fvp/host/map/octree_key_set.h"

namespace fvp::host::map {
namespace {

// Rays are clipped to the map's box / sphere grown by this many voxels, so the clipped
// segment's first and last voxels lie outside the updatable set: the start voxel
// (included by computeRayKeys) and the cut end voxel (excluded by it) never matter.
constexpr double kClipMarginVoxels = 2.0;

struct Interval {
  double t0 = 0.0, t1 = 1.0;
  bool empty() const { return !(t0 <= t1); }
};

// Segment o + t d, t in [0, 1], against an axis-aligned box (slab method).
Interval clipToBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& lo,
                   const Eigen::Vector3d& hi, Interval in) {
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < lo[a] || o[a] > hi[a]) return {1.0, 0.0};
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a];
    double tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    in.t0 = std::max(in.t0, ta);
    in.t1 = std::min(in.t1, tb);
  }
  return in;
}

// The smallest interval holding both (the keep predicate drops what lies between).
Interval hull(const Interval& a, const Interval& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return {std::min(a.t0, b.t0), std::max(a.t1, b.t1)};
}

// Segment o + t d against a sphere.
Interval clipToSphere(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& c,
                      double r, Interval in) {
  const double a = d.squaredNorm();
  if (a == 0.0) return (o - c).squaredNorm() <= r * r ? in : Interval{1.0, 0.0};
  const Eigen::Vector3d f = o - c;
  const double b = f.dot(d);
  const double disc = b * b - a * (f.squaredNorm() - r * r);
  if (disc < 0.0) return {1.0, 0.0};
  const double s = std::sqrt(disc);
  in.t0 = std::max(in.t0, (-b - s) / a);
  in.t1 = std::min(in.t1, (-b + s) / a);
  return in;
}

bool inGrid(const GridGeometry& g, int key_offset, const octomap::OcTreeKey& key,
            std::array<int, 3>& index) {
  for (int a = 0; a < 3; ++a) {
    const std::int64_t i = std::int64_t{key[a]} - key_offset - g.first_voxel[a];
    if (i < 0 || i >= g.dims[a]) return false;
    index[a] = static_cast<int>(i);
  }
  return true;
}

template <typename Tree>
void setSensorModel(Tree& tree, const OccupancyModel& model) {
  tree.setProbHit(model.prob_hit);
  tree.setProbMiss(model.prob_miss);
  tree.setClampingThresMin(model.clamp_min);
  tree.setClampingThresMax(model.clamp_max);
  tree.setOccupancyThres(model.occupied_prob);
}

// The key sets of one scan (OctoMap's computeUpdate), per map and kind of update.
struct ScanKeys {
  enum Kind { kCoarseFree, kCoarseHit, kFineFree, kFineRoiHit, kFineOtherHit, kKindCount };
  std::array<OcTreeKeySet, kKindCount> sets;
  OcTreeKeySet& operator[](Kind kind) { return sets[kind]; }
  const OcTreeKeySet& operator[](Kind kind) const { return sets[kind]; }
};

// Which shard of the merged sets a key belongs to: high hash bits, so the shard does not
// correlate with the slot a set probes first (low bits).
std::size_t shardOf(OcTreeKeySet::Packed packed, std::size_t shard_count) {
  return static_cast<std::size_t>(OcTreeKeySet::hash(packed) >> 40) % shard_count;
}

// One update of one key as a sortable word: the key's Morton code (bit b of key[0], [1],
// [2] at 3b, 3b+1, 3b+2: the child index OctoMap descends by at depth 15 - b) in bits
// 2..49, the update in bits 0..1. Sorted, these are the tree's depth-first order.
enum UpdateKind : std::uint64_t { kUpdateFree = 0, kUpdateHit = 1, kUpdateRoiHit = 2 };

std::uint64_t spreadBits3(std::uint64_t v) {  // 16 bits to every third of 48
  v &= 0xffff;
  v = (v | v << 16) & 0x0000ff0000ffull;
  v = (v | v << 8) & 0x00f00f00f00full;
  v = (v | v << 4) & 0x0c30c30c30c3ull;
  v = (v | v << 2) & 0x249249249249ull;
  return v;
}

std::uint64_t compactBits3(std::uint64_t v) {  // the inverse of spreadBits3
  v &= 0x249249249249ull;
  v = (v | v >> 2) & 0x0c30c30c30c3ull;
  v = (v | v >> 4) & 0x00f00f00f00full;
  v = (v | v >> 8) & 0x0000ff0000ffull;
  v = (v | v >> 16) & 0xffff;
  return v;
}

std::uint64_t treeOrder(OcTreeKeySet::Packed packed, UpdateKind update) {
  const std::uint64_t morton =
      spreadBits3(packed) | spreadBits3(packed >> 16) << 1 | spreadBits3(packed >> 32) << 2;
  return morton << 2 | update;
}

octomap::OcTreeKey keyOfTreeOrder(std::uint64_t entry) {
  const std::uint64_t morton = entry >> 2;
  return octomap::OcTreeKey(static_cast<octomap::key_type>(compactBits3(morton)),
                            static_cast<octomap::key_type>(compactBits3(morton >> 1)),
                            static_cast<octomap::key_type>(compactBits3(morton >> 2)));
}

UpdateKind updateOfTreeOrder(std::uint64_t entry) {
  return static_cast<UpdateKind>(entry & 3);
}

// The parts sorted in parallel, then merged pairwise, a round of merges in parallel.
// (libstdc++'s parallel mode cannot be included beside OctoMap's std::tr1 headers.)
std::vector<std::uint64_t> sortedUnion(std::vector<std::vector<std::uint64_t>> parts) {
  if (parts.empty()) return {};
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(parts.size()); ++i) {
    std::sort(parts[static_cast<std::size_t>(i)].begin(), parts[static_cast<std::size_t>(i)].end());
  }
  while (parts.size() > 1) {
    std::vector<std::vector<std::uint64_t>> merged((parts.size() + 1) / 2);
#pragma omp parallel for schedule(dynamic, 1)
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(merged.size()); ++i) {
      const auto m = static_cast<std::size_t>(i);
      if (2 * m + 1 == parts.size()) {
        merged[m] = std::move(parts[2 * m]);
        continue;
      }
      const auto& a = parts[2 * m];
      const auto& b = parts[2 * m + 1];
      merged[m].resize(a.size() + b.size());
      std::merge(a.begin(), a.end(), b.begin(), b.end(), merged[m].begin());
    }
    parts = std::move(merged);
  }
  return std::move(parts.front());
}

// Keys are 16 bit: every lattice index the engine turns into a key must lie within
// OctoMap's +-32768 voxels.
void checkKeyRange(const char* name, const std::array<std::int64_t, 3>& lo_index,
                   const std::array<std::int64_t, 3>& end_index, int key_offset) {
  for (int a = 0; a < 3; ++a) {
    if (lo_index[a] + key_offset < 0 ||
        end_index[a] - 1 + key_offset > std::numeric_limits<octomap::key_type>::max()) {
      throw std::invalid_argument(std::string("octomap engine: the ") + name +
                                  " lies outside OctoMap's key range (+-32768 voxels around "
                                  "the origin)");
    }
  }
}

void checkKeyRange(const char* name, const GridGeometry& g, int key_offset) {
  std::array<std::int64_t, 3> lo, end;
  for (int a = 0; a < 3; ++a) {
    lo[a] = g.first_voxel[a];
    end[a] = std::int64_t{g.first_voxel[a]} + g.dims[a];
  }
  checkKeyRange(name, lo, end, key_offset);
}

// computeRayKeys on the part of the ray o -> e inside `clip`, keeping the keys `keep` accepts.
template <typename Tree, typename Keep>
void addFreeKeys(const Tree& tree, const octomap::point3d& o, const octomap::point3d& e,
                 const Interval& clip, octomap::KeyRay& key_ray, const Keep& keep,
                 OcTreeKeySet& out) {
  if (clip.empty()) return;
  const Eigen::Vector3d od(o.x(), o.y(), o.z());
  const Eigen::Vector3d dd = Eigen::Vector3d(e.x(), e.y(), e.z()) - od;
  auto at = [&](double t) {
    const Eigen::Vector3d p = od + t * dd;
    return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                            static_cast<float>(p.z()));
  };
  const octomap::point3d a = clip.t0 > 0.0 ? at(clip.t0) : o;
  const octomap::point3d b = clip.t1 < 1.0 ? at(clip.t1) : e;
  if (!tree.computeRayKeys(a, b, key_ray)) return;
  for (const octomap::OcTreeKey& key : key_ray) {
    if (keep(key)) out.insert(key);
  }
}

/// Where a scan updates the two trees: the coarse grid, and the fine map (the Cluster
/// Region, and with an observation_box extent every voxel of the box too).
struct ScanTarget {
  const octomap::OcTree& coarse;
  const RoiOcTree& fine;
  const GridGeometry& coarse_grid;
  const GridGeometry& fine_grid;
  fvp_region fine_region;
  int key_offset = 0;
  bool whole_box = false;
  std::array<std::int64_t, 3> box_lo, box_hi;  // the observation box on the fine lattice
  Eigen::Vector3d region_center;
  double region_radius_m = 0.0;

  bool inFineRegion(const octomap::OcTreeKey& key) const {
    std::array<int, 3> i;
    return inGrid(fine_grid, key_offset, key, i) &&
           fvp_region_contains(&fine_region, i[0], i[1], i[2]);
  }
  bool inCoarseGrid(const octomap::OcTreeKey& key) const {
    std::array<int, 3> i;
    return inGrid(coarse_grid, key_offset, key, i);
  }
  // The region is always updated (it may reach beyond the box); with an observation_box
  // extent, every voxel of the box too.
  bool inFineMap(const octomap::OcTreeKey& key) const {
    if (inFineRegion(key)) return true;
    if (!whole_box) return false;
    for (int a = 0; a < 3; ++a) {
      const std::int64_t i = std::int64_t{key[a]} - key_offset;
      if (i < box_lo[a] || i >= box_hi[a]) return false;
    }
    return true;
  }

  std::vector<ScanKeys> collectKeys(const octomap::point3d& origin,
                                    const std::vector<accel::ScanPoint>& points) const;
};

// Each thread collects the keys of its rays into its own sets.
std::vector<ScanKeys> ScanTarget::collectKeys(const octomap::point3d& origin,
                                              const std::vector<accel::ScanPoint>& points) const {
  const double cs = coarse_grid.voxel_size_m, fs = fine_grid.voxel_size_m;
  Eigen::Vector3d coarse_lo, coarse_hi, fine_lo, fine_hi;
  for (int a = 0; a < 3; ++a) {
    coarse_lo[a] = (coarse_grid.first_voxel[a] - kClipMarginVoxels) * cs;
    coarse_hi[a] = (coarse_grid.first_voxel[a] + coarse_grid.dims[a] + kClipMarginVoxels) * cs;
    fine_lo[a] = (fine_grid.first_voxel[a] - kClipMarginVoxels) * fs;
    fine_hi[a] = (fine_grid.first_voxel[a] + fine_grid.dims[a] + kClipMarginVoxels) * fs;
  }
  const double region_clip_radius = region_radius_m + kClipMarginVoxels * fs;
  const auto keepCoarse = [this](const octomap::OcTreeKey& key) { return inCoarseGrid(key); };
  const auto keepFine = [this](const octomap::OcTreeKey& key) { return inFineMap(key); };

  // The ray as OctoMap sees it: float end points (clipping is done in double from them).
  const Eigen::Vector3d of(origin.x(), origin.y(), origin.z());
  const auto ray_count = static_cast<std::int64_t>(points.size());
  std::vector<ScanKeys> per_thread(static_cast<std::size_t>(std::max(1, omp_get_max_threads())));
#pragma omp parallel
  {
    ScanKeys& local = per_thread[static_cast<std::size_t>(omp_get_thread_num())];
    octomap::KeyRay key_ray;
    // Large chunks of neighbouring pixels: a voxel seen by many rays is then mostly
    // collected by one thread, which keeps the merge small.
#pragma omp for schedule(dynamic, 4096)
    for (std::int64_t r = 0; r < ray_count; ++r) {
      const accel::ScanPoint& point = points[static_cast<std::size_t>(r)];
      const octomap::point3d end(point.x_m, point.y_m, point.z_m);
      const Eigen::Vector3d dd = Eigen::Vector3d(end.x(), end.y(), end.z()) - of;
      addFreeKeys(coarse, origin, end, clipToBox(of, dd, coarse_lo, coarse_hi, {}), key_ray,
                  keepCoarse, local[ScanKeys::kCoarseFree]);
      const Interval region_clip = clipToSphere(of, dd, region_center, region_clip_radius,
                                                clipToBox(of, dd, fine_lo, fine_hi, {}));
      const Interval fine_clip =
          whole_box ? hull(region_clip, clipToBox(of, dd, coarse_lo, coarse_hi, {})) : region_clip;
      addFreeKeys(fine, origin, end, fine_clip, key_ray, keepFine, local[ScanKeys::kFineFree]);
      if (point.flags & FVP_POINT_HIT) {
        octomap::OcTreeKey key;
        if (coarse.coordToKeyChecked(end, key) && inCoarseGrid(key)) {
          local[ScanKeys::kCoarseHit].insert(key);
        }
        if (fine.coordToKeyChecked(end, key) && inFineMap(key)) {
          local[point.flags & FVP_POINT_ROI ? ScanKeys::kFineRoiHit : ScanKeys::kFineOtherHit]
              .insert(key);
        }
      }
    }
  }
  return per_thread;
}

// Merge: shard s of every kind takes the keys of that shard from every thread's sets (no
// lock, each key inserted once more).
std::vector<ScanKeys> mergeByShard(const std::vector<ScanKeys>& per_thread) {
  const std::size_t shard_count = per_thread.size();
  std::vector<ScanKeys> shards(shard_count);
  const auto merge_jobs = static_cast<std::int64_t>(shard_count * ScanKeys::kKindCount);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t job = 0; job < merge_jobs; ++job) {
    const std::size_t shard = static_cast<std::size_t>(job) / ScanKeys::kKindCount;
    const auto kind = static_cast<ScanKeys::Kind>(job % ScanKeys::kKindCount);
    OcTreeKeySet& merged = shards[shard][kind];
    for (const ScanKeys& local : per_thread) {
      local[kind].forEachPacked([&](OcTreeKeySet::Packed packed) {
        if (shardOf(packed, shard_count) == shard) merged.insertPacked(packed);
      });
    }
  }
  return shards;
}

// Occupied wins over free, and an ROI end point makes the voxel an ROI hit (a key's kinds all
// live in one shard): each shard's updates of the coarse and the fine tree, in tree order.
void updatesOfShards(const std::vector<ScanKeys>& shards,
                     std::vector<std::vector<std::uint64_t>>& coarse_updates,
                     std::vector<std::vector<std::uint64_t>>& fine_updates) {
  const std::size_t shard_count = shards.size();
  coarse_updates.assign(shard_count, {});
  fine_updates.assign(shard_count, {});
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t s = 0; s < static_cast<std::int64_t>(shard_count); ++s) {
    const ScanKeys& shard = shards[static_cast<std::size_t>(s)];
    const OcTreeKeySet& coarse_hit = shard[ScanKeys::kCoarseHit];
    const OcTreeKeySet& roi_hit = shard[ScanKeys::kFineRoiHit];
    const OcTreeKeySet& other_hit = shard[ScanKeys::kFineOtherHit];
    std::vector<std::uint64_t>& coarse_out = coarse_updates[static_cast<std::size_t>(s)];
    std::vector<std::uint64_t>& fine_out = fine_updates[static_cast<std::size_t>(s)];
    shard[ScanKeys::kCoarseFree].forEachPacked([&](OcTreeKeySet::Packed p) {
      if (!coarse_hit.containsPacked(p)) coarse_out.push_back(treeOrder(p, kUpdateFree));
    });
    coarse_hit.forEachPacked(
        [&](OcTreeKeySet::Packed p) { coarse_out.push_back(treeOrder(p, kUpdateHit)); });
    shard[ScanKeys::kFineFree].forEachPacked([&](OcTreeKeySet::Packed p) {
      if (!roi_hit.containsPacked(p) && !other_hit.containsPacked(p)) {
        fine_out.push_back(treeOrder(p, kUpdateFree));
      }
    });
    roi_hit.forEachPacked(
        [&](OcTreeKeySet::Packed p) { fine_out.push_back(treeOrder(p, kUpdateRoiHit)); });
    other_hit.forEachPacked([&](OcTreeKeySet::Packed p) {
      if (!roi_hit.containsPacked(p)) fine_out.push_back(treeOrder(p, kUpdateHit));
    });
  }
}

}  // namespace

OctomapMapEngine::OctomapMapEngine(const MapConfig& config, const ClusterRegion& region)
    : MapEngine(config, region) {
  config.validate("octomap engine config");
  if (!(region.radius_m() > 0.0) || !region.center_m().allFinite()) {
    throw std::invalid_argument(
        "octomap engine: the Cluster Region needs a finite centre and a "
        "positive radius");
  }
  coarse_grid_ = coarseGridGeometry(config);
  coarse_ = std::make_unique<octomap::OcTree>(config.coarse_voxel_size_m);
  setSensorModel(*coarse_, config.model);
  key_offset_ = coarse_->coordToKey(0.0);  // tree_max_val: the key of lattice index 0

  // The observation box as the coarse grid holds it (snapped outward to whole 8-voxel
  // bricks), on the fine lattice: where an observation_box extent updates the fine tree.
  const double ratio = config.coarse_voxel_size_m / config.fine_voxel_size_m;
  for (int a = 0; a < 3; ++a) {
    fine_box_lo_[a] = std::llround(coarse_grid_.first_voxel[a] * ratio);
    fine_box_hi_[a] = std::llround((coarse_grid_.first_voxel[a] + coarse_grid_.dims[a]) * ratio);
  }
  checkKeyRange("coarse grid", coarse_grid_, key_offset_);
  if (config.fine_map_extent == FineMapExtent::kObservationBox)
    checkKeyRange("observation box at the fine voxel size", fine_box_lo_, fine_box_hi_,
                  key_offset_);
  placeFineMap();
}

void OctomapMapEngine::placeFineMap() {
  GridGeometry grid = fineGridGeometry(config(), region());
  checkKeyRange("fine grid", grid, key_offset_);
  fine_grid_ = grid;
  fine_region_ = regionInGrid(fine_grid_, region());
  fine_ = std::make_unique<RoiOcTree>(config().fine_voxel_size_m);
  setSensorModel(*fine_, config().model);
  distance_vox_.clear();
  distance_max_d_m_ = -1.0;
  distance_scans_ = 0;
}

OctomapMapEngine::~OctomapMapEngine() = default;

octomap::OcTreeKey OctomapMapEngine::coarseKey(const std::array<int, 3>& index) const {
  octomap::OcTreeKey key;
  for (int a = 0; a < 3; ++a) {
    key[a] = static_cast<octomap::key_type>(coarse_grid_.first_voxel[a] + index[a] + key_offset_);
  }
  return key;
}

octomap::OcTreeKey OctomapMapEngine::fineKey(const std::array<int, 3>& index) const {
  octomap::OcTreeKey key;
  for (int a = 0; a < 3; ++a) {
    key[a] = static_cast<octomap::key_type>(fine_grid_.first_voxel[a] + index[a] + key_offset_);
  }
  return key;
}

void OctomapMapEngine::integrateScan(const Eigen::Vector3d& sensor_origin_m,
                                     const std::vector<accel::ScanPoint>& points,
                                     ScanStats& stats) {
  if (!sensor_origin_m.allFinite()) {
    throw std::invalid_argument("octomap engine: the sensor origin is not finite");
  }
  // 1. The rays were validated and cut by prepareScanPoints (MapEngine::integrate).
  const octomap::point3d origin(static_cast<float>(sensor_origin_m.x()),
                                static_cast<float>(sensor_origin_m.y()),
                                static_cast<float>(sensor_origin_m.z()));

  // 2. Key sets (computeUpdate): each thread collects the keys of its rays into its own
  //    sets, then the sets are merged by shard in parallel (no lock, each key inserted
  //    once more), then applied serially (OctoMap's tree is not thread-safe).
  const ScanTarget target{*coarse_,
                          *fine_,
                          coarse_grid_,
                          fine_grid_,
                          fine_region_,
                          key_offset_,
                          config().fine_map_extent == FineMapExtent::kObservationBox,
                          fine_box_lo_,
                          fine_box_hi_,
                          region().center_m(),
                          region().radius_m()};
  std::vector<ScanKeys> shards = mergeByShard(target.collectKeys(origin, points));

  // 3. Occupied wins over free, and an ROI end point makes the voxel an ROI hit. Then one
  //    update per key, as insertPointCloud, in the order the tree is laid out (Morton
  //    order, so consecutive updates share most of their path from the root) and lazily
  //    (inner nodes and pruning once for the whole scan, insertPointCloud's lazy_eval).
  //    Together: 3.9 s -> 1.3 s for the serial update of the bench frame over hash order
  //    and eager inner nodes (BM_ScanIntegrateFineBox).
  std::vector<std::vector<std::uint64_t>> coarse_updates, fine_updates;
  updatesOfShards(shards, coarse_updates, fine_updates);
  shards.clear();
  const std::vector<std::uint64_t> coarse_sorted = sortedUnion(std::move(coarse_updates));
  const std::vector<std::uint64_t> fine_sorted = sortedUnion(std::move(fine_updates));
  // Every updated voxel of a grid goes to the change log (readers refresh its brick).
  BrickChangeLog& coarse_log = changeLog(MapLevel::kCoarse);
  BrickChangeLog& fine_log = changeLog(MapLevel::kFine);
  std::array<int, 3> index;
  for (const std::uint64_t entry : coarse_sorted) {
    const octomap::OcTreeKey key = keyOfTreeOrder(entry);
    coarse_->updateNode(key, updateOfTreeOrder(entry) != kUpdateFree, /*lazy_eval=*/true);
    if (inGrid(coarse_grid_, key_offset_, key, index)) coarse_log.markVoxel(index);
  }
  for (const std::uint64_t entry : fine_sorted) {
    const UpdateKind update = updateOfTreeOrder(entry);
    const octomap::OcTreeKey key = keyOfTreeOrder(entry);
    if (inGrid(fine_grid_, key_offset_, key, index)) fine_log.markVoxel(index);
    fine_->updateNodeAndRoi(key, update != kUpdateFree,
                            update == kUpdateRoiHit ? RoiOcTree::RoiUpdate::kHit
                            : update == kUpdateHit  ? RoiOcTree::RoiUpdate::kMiss
                                                    : RoiOcTree::RoiUpdate::kNone,
                            /*lazy_eval=*/true);
  }
  coarse_->updateInnerOccupancy();
  coarse_->prune();
  fine_->updateInnerOccupancy();
  fine_->prune();
  coarse_log.commitVoxels();
  fine_log.commitVoxels();
  stats.coarse_voxels_updated = coarse_sorted.size();
  stats.fine_voxels_updated = fine_sorted.size();
}

VoxelClass OctomapMapEngine::coarseClassAt(const std::array<int, 3>& index) const {
  for (int a = 0; a < 3; ++a) {
    if (index[a] < 0 || index[a] >= coarse_grid_.dims[a]) return VoxelClass::kUnknown;
  }
  const octomap::OcTreeNode* node = coarse_->search(coarseKey(index));
  if (node == nullptr) return VoxelClass::kUnknown;
  return classifyLogOdds(node->getLogOdds(), config().model.occupiedLogOdds());
}

VoxelState OctomapMapEngine::fineStateAt(const std::array<int, 3>& index) const {
  for (int a = 0; a < 3; ++a) {
    if (index[a] < 0 || index[a] >= fine_grid_.dims[a]) return {};
  }
  if (!fvp_region_contains(&fine_region_, index[0], index[1], index[2])) return {};
  const RoiOcTreeNode* node = fine_->search(fineKey(index));
  if (node == nullptr) return {};
  return {classifyLogOdds(node->getLogOdds(), config().model.occupiedLogOdds()), node->isRoi()};
}

VoxelClass OctomapMapEngine::coarseClass(const Eigen::Vector3d& p_m) const {
  std::array<int, 3> index;
  if (!coarse_grid_.gridIndex(p_m, index)) return VoxelClass::kUnknown;
  return coarseClassAt(index);
}

VoxelState OctomapMapEngine::fineState(const Eigen::Vector3d& p_m) const {
  std::array<int, 3> index;
  if (!fine_grid_.gridIndex(p_m, index)) return {};
  return fineStateAt(index);
}

void OctomapMapEngine::exportCoarse(const std::filesystem::path& bt_path) const {
  writeCoarseBt(*coarse_, bt_path);
}

void OctomapMapEngine::exportFine(const std::filesystem::path& ot_path) const {
  writeFineOt(*fine_, ot_path);
}

namespace {

// Calls f(index) for every voxel of `grid` that the leaf (lattice corner `corner`, n voxels
// per edge) covers, the loops clipped to the grid: a pruned leaf may be far larger.
template <typename F>
void forLeafVoxelsInGrid(const GridGeometry& grid, const std::array<std::int64_t, 3>& corner,
                         std::int64_t n, F&& f) {
  std::array<std::int64_t, 3> lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::max<std::int64_t>(corner[a] - grid.first_voxel[a], 0);
    hi[a] = std::min<std::int64_t>(corner[a] - grid.first_voxel[a] + n, grid.dims[a]);
  }
  for (std::int64_t z = lo[2]; z < hi[2]; ++z)
    for (std::int64_t y = lo[1]; y < hi[1]; ++y)
      for (std::int64_t x = lo[0]; x < hi[0]; ++x)
        f(std::array<int, 3>{static_cast<int>(x), static_cast<int>(y), static_cast<int>(z)});
}

// The leaves of `tree` that overlap `grid`'s box, by OctoMap's bounding-box iterator: with
// fine_map_extent observation_box the fine tree holds far more than the grid's cube.
template <typename Tree, typename F>
void forLeavesOverlappingGrid(const Tree& tree, const GridGeometry& grid, int key_offset, F&& f) {
  octomap::OcTreeKey min_key, max_key;
  for (int a = 0; a < 3; ++a) {
    min_key[a] = static_cast<octomap::key_type>(grid.first_voxel[a] + key_offset);
    max_key[a] =
        static_cast<octomap::key_type>(grid.first_voxel[a] + grid.dims[a] - 1 + key_offset);
  }
  const unsigned depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs_bbx(min_key, max_key); it != tree.end_leafs_bbx(); ++it) {
    const octomap::OcTreeKey key = it.getIndexKey();
    const std::array<std::int64_t, 3> corner{std::int64_t{key[0]} - key_offset,
                                             std::int64_t{key[1]} - key_offset,
                                             std::int64_t{key[2]} - key_offset};
    f(*it, corner, std::int64_t{1} << (depth - it.getDepth()));
  }
}

// Grid indices of the occupied leaves of `tree` (pruned leaves expanded to their voxels).
template <typename Tree>
std::vector<std::array<int, 3>> occupiedLeaves(const Tree& tree, const GridGeometry& grid,
                                               int key_offset, float occupied_logodds) {
  std::vector<std::array<int, 3>> voxels;
  forLeavesOverlappingGrid(
      tree, grid, key_offset, [&](const auto& node, const auto& corner, std::int64_t n) {
        if (classifyLogOdds(node.getLogOdds(), occupied_logodds) != VoxelClass::kOccupied) return;
        forLeafVoxelsInGrid(grid, corner, n,
                            [&](const std::array<int, 3>& i) { voxels.push_back(i); });
      });
  return voxels;
}

}  // namespace

std::vector<std::array<int, 3>> OctomapMapEngine::occupiedVoxels(MapLevel level) const {
  const float occupied = config().model.occupiedLogOdds();
  if (level == MapLevel::kCoarse)
    return occupiedLeaves(*coarse_, coarse_grid_, key_offset_, occupied);
  std::vector<std::array<int, 3>> voxels =
      occupiedLeaves(*fine_, fine_grid_, key_offset_, occupied);
  // The tree of an observation_box extent holds the cube's corners outside the region too.
  std::erase_if(voxels, [&](const std::array<int, 3>& i) {
    return !fvp_region_contains(&fine_region_, i[0], i[1], i[2]);
  });
  return voxels;
}

namespace {

// A known fine voxel as the leaf iteration yields it (pruned leafs expanded).
struct KnownVoxel {
  std::array<int, 3> index;
  const RoiOcTreeNode* node;
};

// Every voxel of the fine grid's region the tree knows: its leafs at the fine depth, a
// pruned leaf standing for its whole cube of voxels.
std::vector<KnownVoxel> knownFineVoxels(const RoiOcTree& tree, const GridGeometry& grid,
                                        const fvp_region& region, int key_offset) {
  std::vector<KnownVoxel> voxels;
  forLeavesOverlappingGrid(tree, grid, key_offset,
                           [&](const RoiOcTreeNode& node, const auto& corner, std::int64_t n) {
                             forLeafVoxelsInGrid(grid, corner, n, [&](const std::array<int, 3>& i) {
                               if (fvp_region_contains(&region, i[0], i[1], i[2]))
                                 voxels.push_back({i, &node});
                             });
                           });
  return voxels;
}

}  // namespace

void OctomapMapEngine::updateRoiDistance(double max_d_m) {
  if (!(max_d_m > 0.0)) throw std::invalid_argument("updateRoiDistance: max_d_m must be positive");
  if (distance_max_d_m_ == max_d_m && distance_scans_ == scanCount()) return;
  const double voxel = fine_grid_.voxel_size_m;
  // The grid engine's window radius: the same cap in voxels on both engines.
  const int radius_vox = std::max(1, static_cast<int>(std::ceil(max_d_m / voxel)));
  const auto& dims = fine_grid_.dims;
  // The previous field, to record in the change log the voxels whose d_i this one changes.
  const std::vector<float> previous =
      distance_max_d_m_ == max_d_m ? std::move(distance_vox_) : std::vector<float>{};
  distance_vox_.assign(static_cast<std::size_t>(fine_grid_.voxelCount()),
                       static_cast<float>(radius_vox));

  // The obstacles of the transform: known ROI voxels only, as occupied leafs of a plain
  // OcTree on the fine lattice (same resolution, so the same keys). Everything else is
  // left unknown, which DynamicEDT treats as free (treatUnknownAsOccupied = false).
  octomap::OcTree roi_tree(voxel);
  bool any_roi = false;
  for (const KnownVoxel& v : knownFineVoxels(*fine_, fine_grid_, fine_region_, key_offset_)) {
    if (!v.node->isRoi()) continue;
    roi_tree.setNodeValue(fineKey(v.index), roi_tree.getClampingThresMaxLog(),
                          /*lazy_eval=*/true);
    any_roi = true;
  }
  if (any_roi) {
    roi_tree.updateInnerOccupancy();
    const octomap::point3d box_min = roi_tree.keyToCoord(fineKey({0, 0, 0}));
    const octomap::point3d box_max =
        roi_tree.keyToCoord(fineKey({dims[0] - 1, dims[1] - 1, dims[2] - 1}));
    // DynamicEDT saturates at int(maxdist / resolution + 1) cells: R + 0.5 voxels gives
    // R + 1, so every distance below the cap R is propagated; the cap is applied below.
    const auto maxdist_m = static_cast<float>((radius_vox + 0.5) * voxel);
    DynamicEDTOctomap edt(maxdist_m, &roi_tree, box_min, box_max, /*treatUnknownAsOccupied=*/false);
    edt.update(/*updateRealDist=*/false);  // only squared cell distances are read
    for (int z = 0; z < dims[2]; ++z)
      for (int y = 0; y < dims[1]; ++y)
        for (int x = 0; x < dims[0]; ++x) {
          // Squared distance between cell centres in cells (exact integers), converted as
          // the grid engine's kernel does so that equal squares give equal distances.
          const int sq = edt.getSquaredDistanceInCells(roi_tree.keyToCoord(fineKey({x, y, z})));
          if (sq < 0)
            throw std::logic_error("updateRoiDistance: a fine voxel outside DynamicEDT's box");
          distance_vox_[x + dims[0] * (y + static_cast<std::size_t>(dims[1]) * z)] =
              fvp_edt_distance_vox(static_cast<unsigned int>(sq), radius_vox);
        }
  }
  recordDistanceChanges(previous);
  distance_max_d_m_ = max_d_m;
  distance_scans_ = scanCount();
}

void OctomapMapEngine::recordDistanceChanges(const std::vector<float>& previous) {
  BrickChangeLog& log = changeLog(MapLevel::kFine);
  if (previous.size() != distance_vox_.size()) {  // first field or a new cap
    log.markAll();
    return;
  }
  const auto& dims = fine_grid_.dims;
  std::size_t i = 0;
  for (int z = 0; z < dims[2]; ++z)
    for (int y = 0; y < dims[1]; ++y)
      for (int x = 0; x < dims[0]; ++x, ++i)
        if (distance_vox_[i] != previous[i]) log.markVoxel({x, y, z});
  log.commitVoxels();
}

double OctomapMapEngine::roiDistance_m(const std::array<int, 3>& fine_index) const {
  if (distance_max_d_m_ < 0.0)
    throw std::logic_error("roiDistance_m: call updateRoiDistance() first");
  for (int a = 0; a < 3; ++a)
    if (fine_index[a] < 0 || fine_index[a] >= fine_grid_.dims[a]) return distance_max_d_m_;
  const std::size_t dense =
      fine_index[0] +
      fine_grid_.dims[0] *
          (fine_index[1] + static_cast<std::size_t>(fine_grid_.dims[1]) * fine_index[2]);
  return std::min(distance_vox_[dense] * fine_grid_.voxel_size_m, distance_max_d_m_);
}

std::vector<FrontierVoxel> OctomapMapEngine::frontiers() {
  const float occupied = config().model.occupiedLogOdds();
  const std::vector<KnownVoxel> known =
      knownFineVoxels(*fine_, fine_grid_, fine_region_, key_offset_);
  // Unknown space of the fine map: a voxel of the region the tree has no node for.
  auto unknown = [&](int x, int y, int z) {
    if (x < 0 || y < 0 || z < 0 || x >= fine_grid_.dims[0] || y >= fine_grid_.dims[1] ||
        z >= fine_grid_.dims[2])
      return false;
    if (!fvp_region_contains(&fine_region_, x, y, z)) return false;
    return fine_->search(fineKey({x, y, z})) == nullptr;
  };
  constexpr int kFaces[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  std::vector<FrontierVoxel> frontiers;
  const auto count = static_cast<std::int64_t>(known.size());
#pragma omp parallel
  {
    std::vector<FrontierVoxel> local;
#pragma omp for schedule(dynamic, 4096)
    for (std::int64_t k = 0; k < count; ++k) {
      const KnownVoxel& v = known[static_cast<std::size_t>(k)];
      const bool is_roi = v.node->isRoi();
      const bool is_free = classifyLogOdds(v.node->getLogOdds(), occupied) == VoxelClass::kFree;
      if (!is_roi && !is_free) continue;
      const auto [x, y, z] = v.index;
      // Face neighbours first: most known voxels have none unknown, and then the 26-sum
      // for the normal is not needed.
      bool face_unknown = false;
      for (const auto& f : kFaces) {
        if (unknown(x + f[0], y + f[1], z + f[2])) {
          face_unknown = true;
          break;
        }
      }
      if (!face_unknown) continue;
      // Integer sum of -offset over the unknown 26-neighbours, as fvp_frontier_voxel.
      int normal[3] = {0, 0, 0};
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            if ((dx | dy | dz) == 0 || !unknown(x + dx, y + dy, z + dz)) continue;
            normal[0] -= dx;
            normal[1] -= dy;
            normal[2] -= dz;
          }
      FrontierVoxel f;
      f.index = v.index;
      f.center_m = fine_grid_.voxelCenter_m(v.index);
      f.roi_frontier = is_roi;
      f.exploration_frontier = is_free;
      const Eigen::Vector3d n(normal[0], normal[1], normal[2]);
      if (n.squaredNorm() > 0) f.normal = n.normalized();
      local.push_back(f);
    }
#pragma omp critical(fvp_octomap_engine_frontiers)
    frontiers.insert(frontiers.end(), local.begin(), local.end());
  }
  // Threads append in any order: sort by grid index, as the grid engine does.
  std::sort(frontiers.begin(), frontiers.end(), [](const FrontierVoxel& a, const FrontierVoxel& b) {
    return std::tie(a.index[2], a.index[1], a.index[0]) <
           std::tie(b.index[2], b.index[1], b.index[0]);
  });
  return frontiers;
}

}  // namespace fvp::host::map
