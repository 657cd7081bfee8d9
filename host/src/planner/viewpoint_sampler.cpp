#include "fvp/host/planner/viewpoint_sampler.h"

#include <algorithm>
#include <cmath>

#include "fvp/host/core/look_at.h"

namespace fvp::host::planner {

const char* toString(CandidateKind kind) {
  switch (kind) {
    case CandidateKind::kRoi:
      return "roi";
    case CandidateKind::kExploration:
      return "exploration";
    case CandidateKind::kSizing:
      return "sizing";
    case CandidateKind::kRemembered:
      return "remembered";
  }
  return "unknown";
}

bool addsViewSpan(const SizingTarget& target, const Eigen::Vector3d& direction) {
  if (target.seen_from.empty()) return true;
  const double min_cos = std::cos(target.min_angle_deg * M_PI / 180.0);
  return std::any_of(target.seen_from.begin(), target.seen_from.end(),
                     [&](const Eigen::Vector3d& seen) { return seen.dot(direction) <= min_cos; });
}

ViewpointSampler::ViewpointSampler(const PlannerConfig& config, std::uint64_t seed)
    : config_(config), rng_(seed) {}

Eigen::Vector3d ViewpointSampler::randomUnitVector() {
  std::normal_distribution<double> normal(0.0, 1.0);
  for (;;) {
    const Eigen::Vector3d v(normal(rng_), normal(rng_), normal(rng_));
    const double n = v.norm();
    if (n > 1e-9) return v / n;
  }
}

Candidate ViewpointSampler::make(CandidateKind kind, const Eigen::Vector3d& target_m,
                                 const Eigen::Vector3d& direction,
                                 const ReachabilityFn& reachable) {
  std::uniform_real_distribution<double> distance(config_.sensor_min_m, config_.sensor_max_m);
  Candidate c;
  c.kind = kind;
  c.target_m = target_m;
  c.T_world_camera = lookAtPose(target_m + distance(rng_) * direction, target_m);
  c.reachable = !reachable || reachable(c.T_world_camera);
  return c;
}

std::vector<Candidate> ViewpointSampler::sampleRoi(const std::vector<map::FrontierVoxel>& frontiers,
                                                   int count, const ReachabilityFn& reachable) {
  return sample(CandidateKind::kRoi, frontiers, count, reachable);
}

std::vector<Candidate> ViewpointSampler::sampleExploration(
    const std::vector<map::FrontierVoxel>& frontiers, int count, const ReachabilityFn& reachable) {
  return sample(CandidateKind::kExploration, frontiers, count, reachable);
}

std::vector<Candidate> ViewpointSampler::sampleSizing(const std::vector<SizingTarget>& targets,
                                                      int count, const ReachabilityFn& reachable) {
  std::vector<Candidate> out;
  if (targets.empty()) return out;
  std::uniform_int_distribution<std::size_t> pick(0, targets.size() - 1);
  out.reserve(count);
  for (int i = 0; i < count; ++i) {
    const std::size_t t = pick(rng_);
    // Uniform over the directions that add span: rejection from the whole sphere, of which
    // a 30-degree cap around a well-seen direction is 7 %, so a few draws suffice.
    for (int attempt = 0; attempt < kSizingDirectionAttempts; ++attempt) {
      const Eigen::Vector3d dir = randomUnitVector();
      if (!addsViewSpan(targets[t], dir)) continue;
      Candidate c = make(CandidateKind::kSizing, targets[t].center_m, dir, reachable);
      c.sizing_target = static_cast<int>(t);
      out.push_back(c);
      break;
    }
  }
  return out;
}

std::vector<Candidate> ViewpointSampler::sample(CandidateKind kind,
                                                const std::vector<map::FrontierVoxel>& frontiers,
                                                int count, const ReachabilityFn& reachable) {
  const bool roi = kind == CandidateKind::kRoi;
  std::vector<const map::FrontierVoxel*> targets;
  for (const auto& f : frontiers)
    if (roi ? f.roi_frontier : f.exploration_frontier) targets.push_back(&f);
  std::vector<Candidate> out;
  if (targets.empty()) return out;
  std::uniform_int_distribution<std::size_t> pick(0, targets.size() - 1);
  out.reserve(count);
  for (int i = 0; i < count; ++i) {
    const map::FrontierVoxel& t = *targets[pick(rng_)];
    // ROI-targeted: a random direction; exploration: along the frontier's normal.
    const Eigen::Vector3d dir = !roi && t.normal.squaredNorm() > 0.0
                                    ? Eigen::Vector3d(t.normal.normalized())
                                    : randomUnitVector();
    out.push_back(make(kind, t.center_m, dir, reachable));
  }
  return out;
}

}  // namespace fvp::host::planner
