// BM_View/<backend>: the robot's compute for one captured view, renderer excluded: perception
// (stereo matching, tag, segmentation, clouds), mapping (scan integration), TSDF fusion,
// planning (one sampling round with its snapshot refresh and gains) and sizing (the automatic
// stop's sizing of the cluster), each through the library's setup (NbvSetup::makeWork) as a
// trial runs them. Workload: simulated world 1, six views on a 120 degree orbit rendered once;
// each iteration starts a fresh cluster, takes the first five views untimed (perceived, mapped,
// planned on, so the snapshot is refreshed incrementally as in a trial) and times the sixth.
// Checks: the cpu backend's sizing of the six views matches the world's fruitlets (every one
// within 1 mm), and every backend ranks the same best view and gives the same sizes as the cpu
// backend (the determinism contract, docs/kernels.md). Counters: each stage's milliseconds.
// Not in it: the arm's obstacle update and goal checks (the arm's work, BM_MotionPlan).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_common.h"
#include "fvp/host/nbv/nbv_setup.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"

namespace fvp::bench {
namespace {

using host::nbv::ClusterWork;
using host::nbv::NbvSetup;
using host::nbv::NbvSetupOptions;
using Clock = std::chrono::steady_clock;

constexpr int kViews = 6;
constexpr double kArcDeg = 120.0;
constexpr double kSizeToleranceMm = 1.0;

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

struct Workload {
  robot::sim::World world;
  std::vector<host::StereoFrame> frames;
  host::nbv::ClusterTarget target;
};

const Workload& workload() {
  static const Workload w = [] {
    Workload out{robot::sim::World::generate(robot::sim::WorldConfig{}, 1), {}, {}};
    const robot::sim::StereoRenderer renderer(out.world);
    for (const Eigen::Isometry3d& pose : robot::sim::orbitViews(out.world, kViews, kArcDeg))
      out.frames.push_back(renderer.render(pose));
    out.target.tag_id = out.world.tag().tag_id;
    out.target.T_world_start_camera = out.frames.front().T_world_camera;
    out.target.center_m = out.world.clusterCenter_m();
    return out;
  }();
  return w;
}

/// What the timed view gave, and each stage's wall time.
struct ViewOutcome {
  double perception_s = 0, stereo_s = 0, mapping_s = 0, tsdf_s = 0, session_other_s = 0;
  double planning_s = 0, sizing_s = 0;
  std::optional<Eigen::Isometry3d> best_view;
  std::vector<double> sizes_mm;
  std::vector<Eigen::Vector3d> centers_m;
  double total_s() const {
    return perception_s + mapping_s + tsdf_s + session_other_s + planning_s + sizing_s;
  }
};

/// One sampling round on the work's map from the view's pose, every candidate reachable.
std::optional<Eigen::Isometry3d> planOnce(ClusterWork& work, const Eigen::Isometry3d& T_now) {
  host::planner::PlanStep step;
  const auto all = [](const Eigen::Isometry3d&) { return true; };
  const auto ranking = work.planner->rank(*work.session->map(), T_now, all, 0, step);
  if (!ranking || ranking->order.empty()) return std::nullopt;
  return ranking->candidates[ranking->order.front()].T_world_camera;
}

/// A fresh cluster through the first kViews - 1 views, untimed, then the last one timed.
ViewOutcome runView(NbvSetup& setup, const NbvSetupOptions& options) {
  const Workload& w = workload();
  std::unique_ptr<ClusterWork> work = setup.makeWork(w.target);
  for (int v = 0; v + 1 < kViews; ++v) {
    work->session->addView(w.frames[v]);
    if (work->session->map()) planOnce(*work, w.frames[v].T_world_camera);
  }
  const host::StereoFrame& frame = w.frames.back();
  ViewOutcome out;
  const auto t_view = Clock::now();
  const host::ViewResult view = work->session->addView(frame);
  const double add_view_s = secondsSince(t_view);
  if (!work->session->map()) throw std::runtime_error("BM_View: no view showed the tag");
  out.perception_s = view.perceive_s;
  out.stereo_s = view.perception.sgbm_s;
  out.mapping_s = view.scan.seconds;
  out.tsdf_s = view.tsdf_s;
  out.session_other_s =
      std::max(0.0, add_view_s - view.perceive_s - view.scan.seconds - view.tsdf_s);
  const auto t_plan = Clock::now();
  out.best_view = planOnce(*work, frame.T_world_camera);
  out.planning_s = secondsSince(t_plan);
  const auto t_size = Clock::now();
  const host::sizing::SizingResult sized = work->session->sizeFruitletsInMapFrame(options.sizing);
  out.sizing_s = secondsSince(t_size);
  for (const auto& f : sized.fruitlets) {
    out.sizes_mm.push_back(f.size_mm);
    out.centers_m.push_back(f.center_m);
  }
  return out;
}

NbvSetupOptions optionsFor(accel::BackendKind kind) {
  NbvSetupOptions options;
  options.backend = kind == accel::BackendKind::kCpu      ? accel::BackendChoice::kCpu
                    : kind == accel::BackendKind::kOpenCl ? accel::BackendChoice::kOpenCl
                                                          : accel::BackendChoice::kVulkan;
  options.stop.rule = host::nbv::StopRule::kAuto;
  return options;
}

/// Every world fruitlet has a sized fruitlet whose centre lies inside it and whose size is
/// within kSizeToleranceMm of its own (empty: so).
std::string checkAgainstTruth(const ViewOutcome& cpu) {
  for (const robot::sim::Fruitlet& f : workload().world.fruitlets()) {
    bool found = false;
    for (std::size_t i = 0; i < cpu.sizes_mm.size(); ++i)
      found = found || ((cpu.centers_m[i] - f.center_m).norm() < f.radius_m &&
                        std::abs(cpu.sizes_mm[i] - f.gtSizeMm()) <= kSizeToleranceMm);
    if (!found) return "fruitlet " + std::to_string(f.index) + " not sized within 1 mm";
  }
  return {};
}

/// The cpu backend's outcome, the reference every backend must repeat.
const ViewOutcome& cpuReference() {
  static const ViewOutcome reference = [] {
    const NbvSetupOptions options = optionsFor(accel::BackendKind::kCpu);
    NbvSetup setup(options);
    return runView(setup, options);
  }();
  return reference;
}

bool sameOutcome(const ViewOutcome& a, const ViewOutcome& b) {
  if (a.best_view.has_value() != b.best_view.has_value() || a.sizes_mm != b.sizes_mm) return false;
  return !a.best_view || a.best_view->matrix() == b.best_view->matrix();
}

void BM_View(benchmark::State& state, accel::BackendKind kind) {
  if (!backendOrSkip(state, kind)) return;
  const NbvSetupOptions options = optionsFor(kind);
  NbvSetup setup(options);
  const ViewOutcome& reference = cpuReference();
  if (const std::string wrong = checkAgainstTruth(reference); !wrong.empty()) {
    state.SkipWithError(("cpu reference: " + wrong).c_str());
    return;
  }
  ViewOutcome sum;
  bool same = true;
  for (auto _ : state) {
    const ViewOutcome view = runView(setup, options);
    state.SetIterationTime(view.total_s());
    same = same && sameOutcome(view, reference);
    sum.perception_s += view.perception_s;
    sum.stereo_s += view.stereo_s;
    sum.mapping_s += view.mapping_s;
    sum.tsdf_s += view.tsdf_s;
    sum.session_other_s += view.session_other_s;
    sum.planning_s += view.planning_s;
    sum.sizing_s += view.sizing_s;
  }
  if (!same) {
    state.SkipWithError("the best view or the sizes differ from the cpu backend's");
    return;
  }
  const double ms = 1e3 / double(state.iterations());
  state.counters["perception_ms"] = sum.perception_s * ms;
  state.counters["stereo_ms"] = sum.stereo_s * ms;
  state.counters["mapping_ms"] = sum.mapping_s * ms;
  state.counters["tsdf_ms"] = sum.tsdf_s * ms;
  state.counters["session_other_ms"] = sum.session_other_s * ms;
  state.counters["planning_ms"] = sum.planning_s * ms;
  state.counters["sizing_ms"] = sum.sizing_s * ms;
  state.counters["fruitlets_sized"] = double(reference.sizes_mm.size());
}

void registerAll() {
  for (accel::BackendKind kind :
       {accel::BackendKind::kCpu, accel::BackendKind::kOpenCl, accel::BackendKind::kVulkan}) {
    const std::string name = "BM_View/" + std::string(accel::toString(kind));
    benchmark::RegisterBenchmark(name.c_str(), BM_View, kind)
        ->Iterations(5)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
  }
}

const bool kRegistered = (registerAll(), true);

}  // namespace
}  // namespace fvp::bench
