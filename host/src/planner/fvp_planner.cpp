#include "fvp/host/planner/fvp_planner.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <nlohmann/json.hpp>
#include <numeric>
#include <stdexcept>

#include "fvp/host/map/map_engine.h"

namespace fvp::host::planner {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

void addTiming(StageTimings& timings, const std::string& stage, double s) {
  for (auto& [name, value] : timings)
    if (name == stage) {
      value += s;
      return;
    }
  timings.emplace_back(stage, s);
}

InfoGainConfig gainConfig(const PlannerConfig& config) {
  config.validate();
  InfoGainConfig g;
  g.max_d_m = config.max_d_m;
  g.mode = parseGainMode(config.gain_mode);
  g.frustum_rays_x = config.frustum_rays_x;
  g.frustum_rays_y = config.frustum_rays_y;
  g.embree_cull = config.embree_cull;
  return g;
}

}  // namespace

FvpPlanner::FvpPlanner(const PlannerConfig& config, std::uint64_t seed, accel::Backend* backend)
    : config_(config),
      sampler_(config, seed * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint64_t>(config.seed)),
      gain_(gainConfig(config), backend),
      u_t_(config.utility_threshold) {}

void FvpPlanner::score(std::vector<Candidate>& candidates, const Eigen::Vector3d& camera_m,
                       EvaluateStats* stats) const {
  std::vector<ViewQuery> queries;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    Candidate& c = candidates[i];
    c.ig = 0.0;
    c.utility = -std::numeric_limits<double>::infinity();
    if (!c.reachable) continue;
    if (c.kind == CandidateKind::kSizing) {
      if (c.sizing_target < 0 || std::size_t(c.sizing_target) >= sizing_targets_.size())
        throw std::logic_error("FvpPlanner::score: a sizing candidate without its target");
      const SizingTarget& t = sizing_targets_[std::size_t(c.sizing_target)];
      const double seen = gain_.visibleFraction(c.position_m(), t.center_m, t.radius_m);
      c.ig = seen >= t.min_visible_fraction ? seen : 0.0;
      c.utility = c.ig - config_.alpha_per_m * (c.position_m() - camera_m).norm();
      continue;
    }
    queries.push_back({candidates[i].T_world_camera, candidates[i].target_m});
    index.push_back(i);
  }
  const std::vector<GainResult> gains = gain_.evaluate(queries, stats);
  for (std::size_t k = 0; k < index.size(); ++k) {
    Candidate& c = candidates[index[k]];
    c.ig = gains[k].ig;
    c.utility = c.ig - config_.alpha_per_m * (c.position_m() - camera_m).norm();
  }
}

std::optional<Ranking> FvpPlanner::rank(map::MapEngine& map,
                                        const Eigen::Isometry3d& T_world_camera_now,
                                        const ReachabilityFn& reachable, std::size_t round,
                                        PlanStep& step) {
  if (round >= static_cast<std::size_t>(config_.max_sampling_rounds)) return std::nullopt;
  auto t = Clock::now();
  if (round == 0) {
    // Updated from what changed (nothing after failed moves; the whole of it for a moved
    // region or a new map, which a scan count alone would miss).
    gain_.refresh(map);
    const double distance_s = gain_.lastRefresh().distance_s;
    // The map's ROI distance field apart from the snapshot: two costs, two owners.
    addTiming(step.timings_s, "roi_distance", distance_s);
    addTiming(step.timings_s, "snapshot", since(t) - distance_s);
    t = Clock::now();
    if (frontiers_map_ != &map || frontiers_scans_ != map.scanCount()) {
      frontiers_ = map.frontiers();
      frontiers_map_ = &map;
      frontiers_scans_ = map.scanCount();
    }
    addTiming(step.timings_s, "frontiers", since(t));
  }
  ++step.sampling_rounds;
  t = Clock::now();
  Ranking ranking;
  std::vector<Candidate>& candidates = ranking.candidates;
  candidates = sampler_.sampleRoi(frontiers_, config_.roi_samples, reachable);
  std::vector<Candidate> exploration =
      sampler_.sampleExploration(frontiers_, config_.exploration_samples, reachable);
  candidates.insert(candidates.end(), exploration.begin(), exploration.end());
  if (config_.sizing_samples > 0 && !sizing_targets_.empty()) {
    std::vector<Candidate> sizing =
        sampler_.sampleSizing(sizing_targets_, config_.sizing_samples, reachable);
    candidates.insert(candidates.end(), sizing.begin(), sizing.end());
  }
  if (config_.camera_clearance_m > 0.0)
    for (Candidate& c : candidates)
      if (c.reachable && gain_.occupiedWithin(c.position_m(), config_.camera_clearance_m)) {
        c.reachable = false;
        ++step.rejected_clearance;
      }
  addTiming(step.timings_s, "sample", since(t));
  t = Clock::now();
  EvaluateStats stats;
  score(candidates, T_world_camera_now.translation(), &stats);
  const double scoring_s = since(t);
  if (config_.embree_cull) addTiming(step.timings_s, "cull", stats.cull_s);
  addTiming(step.timings_s, "info_gain", scoring_s - stats.cull_s);
  step.culled_rays += stats.culled;
  step.gain_rays += stats.rays;

  // Algorithm 1, lines 6-14: the heap as a sort by utility (ties by index: deterministic),
  // cut where the candidates stop being worth a move.
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return candidates[a].utility > candidates[b].utility;
  });
  for (std::size_t i : order) {
    if (!candidates[i].reachable || !(candidates[i].utility > u_t_)) break;
    ranking.order.push_back(i);
  }
  return ranking;
}

void FvpPlanner::roundDone(bool moved) {
  if (moved)
    u_t_ = config_.utility_threshold;  // line 16
  else
    u_t_ *= config_.threshold_decay;  // line 18
}

std::string FvpPlanner::configJson() const {
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(config_.toJson());
  j["gain_device"] = gain_.walkDevice();
  return j.dump();
}

}  // namespace fvp::host::planner
