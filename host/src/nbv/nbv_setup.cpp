#include "fvp/host/nbv/nbv_setup.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fvp/accel/backend.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/nbv/approach_sequence.h"
#include "fvp/host/nbv/loop_observers.h"
#include "fvp/host/nbv/remembered_views.h"
#include "fvp/host/nbv/sizing_guidance.h"
#include "fvp/host/nbv/tour_order.h"
#include "fvp/host/planner/planner_registry.h"

namespace fvp::host::nbv {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The loop clock as an observer sees it: the time, with nothing charged (sizing for a
/// record under the budget rule is not part of the loop).
class UnchargedClock : public LoopClock {
 public:
  explicit UnchargedClock(const LoopClock& clock) : clock_(clock) {}
  double now_s() const override { return clock_.now_s(); }

 private:
  const LoopClock& clock_;
};

/// The tour's costs between where the arm is (node 0) and the start views of the clusters
/// left (nodes 1..): the arm's travel times where it gives them; a pair it cannot time (a
/// start view without collision-free IK, reached through an approach view) is priced at its
/// camera distance times the median seconds per metre of the pairs it timed; camera distances
/// alone when it timed none.
Eigen::MatrixXd tourCosts(const Arm& arm, const std::vector<Eigen::Isometry3d>& poses) {
  const auto n = Eigen::Index(poses.size());
  Eigen::MatrixXd seconds = Eigen::MatrixXd::Zero(n, n), metres = Eigen::MatrixXd::Zero(n, n);
  std::vector<double> seconds_per_metre;
  for (Eigen::Index a = 0; a < n; ++a)
    for (Eigen::Index b = 1; b < n; ++b) {  // nothing returns to node 0
      if (a == b) continue;
      metres(a, b) =
          (poses[std::size_t(a)].translation() - poses[std::size_t(b)].translation()).norm();
      seconds(a, b) = arm.travelTime_s(poses[std::size_t(a)], poses[std::size_t(b)]);
      if (!(seconds(a, b) >= 0.0) || !std::isfinite(seconds(a, b)))  // unknown
        seconds(a, b) = std::numeric_limits<double>::quiet_NaN();
      else if (metres(a, b) > 1e-6)
        seconds_per_metre.push_back(seconds(a, b) / metres(a, b));
    }
  if (seconds_per_metre.empty()) return metres;
  const auto middle = seconds_per_metre.begin() + std::ptrdiff_t(seconds_per_metre.size() / 2);
  std::nth_element(seconds_per_metre.begin(), middle, seconds_per_metre.end());
  for (Eigen::Index a = 0; a < n; ++a)
    for (Eigen::Index b = 0; b < n; ++b)
      if (!std::isfinite(seconds(a, b))) seconds(a, b) = metres(a, b) * *middle;
  return seconds;
}

/// The cluster to visit next: the first of the quickest order through the clusters left, from
/// where the arm is (tour_order.h). Ordered again after every cluster, from where it ended.
std::size_t nextOnTour(const Arm& arm, const std::vector<ClusterTarget>& targets,
                       const std::vector<bool>& visited) {
  std::vector<std::size_t> left;
  std::vector<Eigen::Isometry3d> poses = {arm.cameraPose()};
  for (std::size_t i = 0; i < targets.size(); ++i)
    if (!visited[i]) left.push_back(i), poses.push_back(targets[i].T_world_start_camera);
  if (left.size() == 1) return left.front();
  return left[shortestOpenTour(tourCosts(arm, poses)).front() - 1];
}

}  // namespace

const char* toString(VisitStatus status) {
  switch (status) {
    case VisitStatus::kSized:
      return "sized";
    case VisitStatus::kNoTag:
      return "no_tag";
    case VisitStatus::kUnreachable:
      return "unreachable";
    case VisitStatus::kMoveFailed:
      return "move_failed";
  }
  return "unknown";
}

void StopSpec::validate() const {
  if (!(budget_s > 0.0) || !std::isfinite(budget_s))
    throw std::invalid_argument("setting 'budget_s': expected a positive number of seconds");
  if (max_views && *max_views < 1)
    throw std::invalid_argument("setting 'max_views': expected at least 1");
  completion.validate();
}

void NbvSetupOptions::validate() const {
  const auto& planners = planner::PlannerRegistry::instance();
  if (!planners.contains(planner))
    throw std::invalid_argument("setting 'planner': expected one of " + planners.knownNames() +
                                ", got '" + planner + "'");
  const auto& engines = map::MapEngineRegistry::instance();
  if (!engine.empty() && !engines.contains(engine))
    throw std::invalid_argument("setting 'engine': expected one of " + engines.knownNames() +
                                ", got '" + engine + "'");
  stop.validate();
  perception.validate();
  if (loop.max_consecutive_dropped_frames < 1)
    throw std::invalid_argument("setting 'max_consecutive_dropped_frames': expected at least 1");
  if (!(loop.view_overhead_s >= 0.0) || !std::isfinite(loop.view_overhead_s))
    throw std::invalid_argument("setting 'view_overhead_s': expected a finite number >= 0");
  if (!(remembered_max_shift_m > 0.0) || !std::isfinite(remembered_max_shift_m))
    throw std::invalid_argument("setting 'remembered_max_shift_m': expected a finite number > 0");
}

NbvSetup::NbvSetup(NbvSetupOptions options) : options_(std::move(options)) {
  options_.validate();
  const auto& planners = planner::PlannerRegistry::instance();
  engine_ =
      options_.engine.empty() ? planners.at(options_.planner).default_engine : options_.engine;
  // A missing backend or a bad planner config fails here, before anything moves.
  backend_ = map::createBackendFor(engine_, options_.backend);
  first_planner_ = planner::createPlanner(options_.planner, options_.planner_config,
                                          options_.planner_seed, backend_.get());
}

NbvSetup::~NbvSetup() = default;

namespace {

TagPoseFn tagPoseOf(const MappingSession& session) {
  return [&session]() -> const std::optional<Eigen::Isometry3d>& { return session.T_world_tag(); };
}

}  // namespace

std::unique_ptr<ClusterWork> NbvSetup::makeWork(const ClusterTarget& target, std::size_t index) {
  PerceptionConfig perception = options_.perception;
  if (target.tag_id) perception.tag.tag_id = *target.tag_id;
  if (target.region_center_m) perception.region.center_m = target.region_center_m;
  perception.disparity_window = options_.disparity_window;
  perception.stereo.guided_fine = options_.guided_stereo;
  auto work = std::make_unique<ClusterWork>();
  work->map_config = planner::plannerMapConfig(options_.planner, engine_);
  work->session =
      std::make_unique<MappingSession>(perception, engine_, work->map_config, backend_.get());
  work->session->enableTsdf();
  if (options_.register_views) work->session->enableViewRegistration();
  work->planner = index == 0 && first_planner_
                      ? std::move(first_planner_)
                      : planner::createPlanner(options_.planner, options_.planner_config,
                                               options_.planner_seed + index, backend_.get());
  if (target.memory) {
    auto remembered = std::make_unique<RememberedViews>(
        std::move(work->planner), tagPoseOf(*work->session), target.memory->T_tag_camera);
    work->remembered = remembered.get();
    work->planner = std::move(remembered);
    work->expected = target.memory->fruitlets;
  }
  return work;
}

ClusterRun NbvSetup::runCluster(const NbvRig& rig, ClusterWork& work, LoopObserver* observer) {
  const StopSpec& spec = options_.stop;
  ClusterRun out;
  out.start_s = rig.clock.now_s();
  // The budget is a time on the run's clock: this cluster's cap from its arrival.
  StopCondition stop = StopCondition::budget(out.start_s + spec.budget_s);
  if (spec.max_views) stop = stop || StopCondition::views(*spec.max_views);
  if (spec.cancel)
    stop = stop || StopCondition([&cancel = spec.cancel](const LoopState&) { return cancel(); },
                                 "cancelled");
  LoopObservers observers;
  observers.add(observer);
  UnchargedClock observing_clock(rig.clock);  // before completion: it outlives it
  std::optional<ClusterCompletion> completion;
  std::optional<SizingGuidance> guidance;
  if (spec.rule == StopRule::kAuto) {
    completion.emplace(*work.session, rig.clock, options_.sizing, spec.completion);
    observers.add(&*completion);
    guidance.emplace(*completion, *work.planner, options_.sizing.well_seen_fraction);
    observers.add(&*guidance);  // after completion: it reads completion's sizing
    if (work.remembered)
      guidance->expect(work.expected, tagPoseOf(*work.session), options_.remembered_max_shift_m);
    completion->holdWhile(
        [&g = *guidance] { return g.waitingOnUnconfirmed() || g.waitingOnExpected(); });
    completion->knownWhen([&g = *guidance] { return g.fruitletsKnown(); });
    if (spec.completion.release_left_out)
      completion->releaseWhen(
          [&g = *guidance](const FruitletSnapshot& f) { return g.leftOut(f.center_m); });
    stop = stop || completion->stopCondition();
  } else if (spec.record_size_history) {
    completion.emplace(*work.session, observing_clock, options_.sizing, spec.completion);
    observers.add(&*completion);
  }
  NbvLoop loop(*work.session, *work.planner, rig.camera, rig.arm, rig.clock, options_.loop);
  out.run = loop.run(stop, &observers);
  if (work.remembered) {
    out.memory.emplace();
    out.memory->views = work.remembered->remembered();
    out.memory->views_taken = work.remembered->taken();
    out.memory->fruitlets = work.expected.size();
    if (guidance) {
      out.memory->found = guidance->expectedFound();
      out.memory->gone = guidance->expectedGone();
      out.memory->known = guidance->fruitletsKnown();
    }
  }
  if (guidance) {
    out.sizing_views = guidance->aimedViews();
    out.sizing_targets_dropped = guidance->droppedTargets();
    work.planner->setSizingTargets({});  // they were this cluster's fruitlets
  }
  const auto t_size = Clock::now();
  out.sizing = work.session->sizeFruitlets(options_.sizing);
  out.sizing_wall_s = secondsSince(t_size);
  if (completion) {
    out.size_history = completion->history();
    for (const auto& snapshot : out.size_history) out.sizing_during_loop_s += snapshot.sizing_s;
  }
  return out;
}

// A view that shows no tag (a leaf before it from there, foliage an earlier cluster's views
// put on the way) places no Cluster Region: the next approach view may show it. The views
// taken on the way are the cluster's too.
ClusterRun NbvSetup::runFromApproaches(const NbvRig& rig, ClusterWork& work,
                                       ApproachSequence& approach, LoopObserver* observer,
                                       ClusterVisit& visit, TourResult& tour) {
  ClusterRun out = runCluster(rig, work, observer);
  std::vector<Eigen::Isometry3d> untagged_poses;  // one per untagged view
  int retried = 0;
  while (!work.session->map() && out.run.stop_reason == "no_region" &&
         approach.moveToNext(rig.arm, rig.clock, visit, tour)) {
    untagged_poses.insert(untagged_poses.end(), out.run.camera_poses.begin(),
                          out.run.camera_poses.end());
    ++retried;
    out = runCluster(rig, work, observer);
  }
  out.run.views += static_cast<int>(untagged_poses.size());
  out.run.camera_poses.insert(out.run.camera_poses.begin(), untagged_poses.begin(),
                              untagged_poses.end());
  out.approaches_without_tag = retried;
  return out;
}

TourResult NbvSetup::runTour(const NbvRig& rig, const std::vector<ClusterTarget>& targets,
                             TourObserver* observer) {
  TourResult tour;
  std::vector<bool> visited(targets.size(), false);
  std::unique_ptr<map::MapEngine> carried_map;
  for (std::size_t step = 0; step < targets.size(); ++step) {
    if (options_.stop.cancel && options_.stop.cancel()) break;
    const auto ordering = Clock::now();
    const std::size_t k = nextOnTour(rig.arm, targets, visited);
    // Compute a robot spends too (IK for every pair of start views); none for the last.
    if (step + 1 < targets.size())
      rig.clock.chargeCompute(LoopStage::kPlanning, secondsSince(ordering));
    visited[k] = true;
    const ClusterTarget& target = targets[k];
    ClusterVisit visit;
    visit.index = k;
    visit.arrival_s = rig.clock.now_s();
    // To its start view (unless the arm is there), or, where the arm cannot stand there,
    // the same view from farther out along its axis, then turned.
    ApproachSequence approach(target);
    if (!rig.arm.cameraPose().isApprox(target.T_world_start_camera, 1e-9) &&
        !approach.moveToNext(rig.arm, rig.clock, visit, tour)) {
      visit.move_status = approach.lastMoveStatus();
      visit.status =
          visit.move_status == "unreachable" ? VisitStatus::kUnreachable : VisitStatus::kMoveFailed;
      if (observer) observer->onClusterSkipped(visit);
      tour.visits.push_back(std::move(visit));
      continue;
    }
    visit.move_status = approach.lastMoveStatus();
    std::unique_ptr<ClusterWork> work = makeWork(target, k);
    if (carried_map) work->session->carryOnWith(std::move(carried_map));
    visit.loop_start_s = rig.clock.now_s();
    if (observer) observer->onClusterStart(k, target);
    visit.run = runFromApproaches(rig, *work, approach, observer, visit, tour);
    visit.status = work->session->map() ? VisitStatus::kSized : VisitStatus::kNoTag;
    if (observer) observer->onClusterDone(visit, *work);
    carried_map = std::move(*work->session).releaseMap();
    tour.visits.push_back(std::move(visit));
  }
  tour.map = std::move(carried_map);
  return tour;
}

}  // namespace fvp::host::nbv
