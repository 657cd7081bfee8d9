#include "fvp/host/planner/rvp_planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>

#include "fvp/host/core/look_at.h"
#include "fvp/host/map/map_engine.h"

namespace fvp::host::planner {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

}  // namespace

RvpPlanner::RvpPlanner(const RvpConfig& config, std::uint64_t seed)
    : config_(config),
      rng_(seed * 0xD1B54A32D192ED03ull ^ static_cast<std::uint64_t>(config.seed)),
      snapshot_(InfoGainConfig{}) {
  config_.validate();
}

std::vector<Eigen::Vector3d> RvpPlanner::roiContourTargets(map::MapEngine& map) {
  const map::GridGeometry& g = map.gridGeometry(map::MapLevel::kFine);
  const auto state = [&](const std::array<int, 3>& i) { return map.fineState(g.voxelCenter_m(i)); };
  static constexpr int kFaces[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                       {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  std::set<std::array<int, 3>> targets;
  for (const auto& v : map.occupiedVoxels(map::MapLevel::kFine)) {
    if (!state(v).roi) continue;
    for (const auto& f : kFaces) {
      const std::array<int, 3> n{v[0] + f[0], v[1] + f[1], v[2] + f[2]};
      if (targets.count(n) || state(n).occupancy != map::VoxelClass::kFree) continue;
      for (const auto& h : kFaces) {
        const std::array<int, 3> m{n[0] + h[0], n[1] + h[1], n[2] + h[2]};
        if (map.region().contains(g.voxelCenter_m(m)) &&
            state(m).occupancy == map::VoxelClass::kUnknown) {
          targets.insert(n);
          break;
        }
      }
    }
  }
  std::vector<Eigen::Vector3d> out;
  for (const auto& t : targets) out.push_back(g.voxelCenter_m(t));
  return out;
}

double RvpPlanner::roiGain(const Eigen::Vector3d& target_m, const Eigen::Vector3d& camera_m) const {
  const InfoGainEvaluator::RayCensus c = snapshot_.census(target_m, camera_m);
  if (c.occluded) return -1.0;
  return c.region_voxels ? double(c.unknown_voxels) / c.region_voxels : 0.0;
}

double RvpPlanner::explorationGain(const Eigen::Isometry3d& T) const {
  const int nx = config_.exploration_rays_x, ny = config_.exploration_rays_y;
  const double tx = std::tan(0.5 * config_.exploration_fov_x_deg * M_PI / 180.0);
  const double ty = tx * ny / nx;  // square pixels
  double sum = 0.0;
  for (int v = 0; v < ny; ++v)
    for (int u = 0; u < nx; ++u) {
      const Eigen::Vector3d dir(((u + 0.5) / nx * 2.0 - 1.0) * tx,
                                ((v + 0.5) / ny * 2.0 - 1.0) * ty, 1.0);
      const Eigen::Vector3d end = T * (config_.sensor_max_m * dir.normalized());
      const InfoGainEvaluator::RayCensus c = snapshot_.census(T.translation(), end);
      // Each ray: its unknown region voxels over its length in fine voxels.
      const double length_voxels = config_.sensor_max_m / snapshot_.fineVoxelSize_m();
      sum += c.unknown_voxels / length_voxels;
    }
  return sum / (nx * ny);
}

}  // namespace fvp::host::planner

namespace fvp::host::planner {

std::optional<Ranking> RvpPlanner::rank(map::MapEngine& map,
                                        const Eigen::Isometry3d& T_world_camera_now,
                                        const ReachabilityFn& reachable, std::size_t round,
                                        PlanStep& step) {
  if (round > 0) return std::nullopt;  // one round an iteration
  step.sampling_rounds = 1;
  auto t = Clock::now();
  // Updated from what changed (the whole of it for a moved region or a new map).
  snapshot_.refresh(map);
  const double distance_s = snapshot_.lastRefresh().distance_s;
  // The map's ROI distance field apart from the snapshot: two costs, two owners.
  step.timings_s.emplace_back("roi_distance", distance_s);
  step.timings_s.emplace_back("snapshot", since(t) - distance_s);
  t = Clock::now();
  if (contour_map_ != &map || contour_scans_ != map.scanCount()) {
    contour_ = roiContourTargets(map);
    contour_map_ = &map;
    contour_scans_ = map.scanCount();
  }
  const std::vector<Eigen::Vector3d>& contour = contour_;
  step.timings_s.emplace_back("targets", since(t));

  t = Clock::now();
  const Eigen::Vector3d now = T_world_camera_now.translation();
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> distance(config_.sensor_min_m, config_.sensor_max_m);
  const auto unit = [&] {
    for (;;) {
      const Eigen::Vector3d v(normal(rng_), normal(rng_), normal(rng_));
      if (v.norm() > 1e-9) return Eigen::Vector3d(v.normalized());
    }
  };
  std::vector<Candidate> roi, exploration;
  if (!contour.empty()) {
    std::uniform_int_distribution<std::size_t> pick(0, contour.size() - 1);
    for (int i = 0; i < config_.roi_samples; ++i) {
      Candidate c;
      c.kind = CandidateKind::kRoi;
      c.target_m = contour[pick(rng_)];
      c.T_world_camera = lookAtPose(c.target_m + distance(rng_) * unit(), c.target_m);
      c.reachable = !reachable || reachable(c.T_world_camera);
      c.utility = -std::numeric_limits<double>::infinity();
      if (c.reachable) {
        c.ig = roiGain(c.target_m, c.position_m());
        if (c.ig >= 0.0)
          c.utility = c.ig - config_.alpha_per_m * (c.position_m() - now).norm();
        else
          c.ig = 0.0;  // occluded: dropped from the set
      }
      roi.push_back(c);
    }
  }
  const Eigen::Vector3d centre = map.region().center_m();
  const double r = map.region().radius_m(), h = config_.exploration_box_half_m;
  std::uniform_real_distribution<double> in_box(-h, h), in_region_box(-r, r);
  for (int i = 0; i < config_.exploration_samples; ++i) {
    Candidate c;
    c.kind = CandidateKind::kExploration;
    const Eigen::Vector3d p = centre + Eigen::Vector3d(in_box(rng_), in_box(rng_), in_box(rng_));
    c.target_m =
        centre + Eigen::Vector3d(in_region_box(rng_), in_region_box(rng_), in_region_box(rng_));
    c.T_world_camera = lookAtPose(p, c.target_m);
    c.reachable = !reachable || reachable(c.T_world_camera);
    c.utility = -std::numeric_limits<double>::infinity();
    if (c.reachable) {
      c.ig = explorationGain(c.T_world_camera);
      c.utility = c.ig - config_.alpha_per_m * (c.position_m() - now).norm();
    }
    exploration.push_back(c);
  }
  step.timings_s.emplace_back("sample_and_gain", since(t));

  // The ROI set when its best utility exceeds the threshold, else exploration.
  double best_roi = -std::numeric_limits<double>::infinity();
  for (const auto& c : roi) best_roi = std::max(best_roi, c.utility);
  const bool use_roi = best_roi > config_.roi_utility_threshold;
  Ranking ranking;
  ranking.candidates = use_roi ? roi : exploration;
  const auto& other = use_roi ? exploration : roi;
  const std::size_t chosen_set = ranking.candidates.size();
  ranking.candidates.insert(ranking.candidates.end(), other.begin(), other.end());
  std::vector<std::size_t> order(chosen_set);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return ranking.candidates[a].utility > ranking.candidates[b].utility;
  });
  for (std::size_t i : order) {
    const Candidate& c = ranking.candidates[i];
    if (!c.reachable || !std::isfinite(c.utility)) break;
    ranking.order.push_back(i);
  }
  return ranking;
}

}  // namespace fvp::host::planner
