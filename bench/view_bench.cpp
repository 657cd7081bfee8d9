// BM_View/<backend>: the robot's compute for one captured view, renderer excluded, in the
// order the loop runs it with the automatic stop (NbvLoop, NbvSetup::runCluster): perception
// (stereo matching, tag, segmentation, clouds), mapping (scan integration), TSDF fusion, the
// stop's sizing of the cluster (ClusterCompletion), its guidance to the planner (sizing
// targets) and planning (round 0: ROI distance, snapshot refresh, sampling, gains), on the
// session and planner of the library's setup (NbvSetup::makeWork). Workload: simulated world
// 1, six views on a 120 degree orbit rendered once; each iteration starts a fresh cluster,
// takes the first five views untimed (so the planner's snapshot is refreshed incrementally,
// as in a trial) and times the sixth. Checks: the cpu backend's sizes after the six views
// match the world's fruitlets (one to one as the trials score them, each within 1 mm, its
// centre inside it), and every backend ranks the same best view and gives the same sizes and
// centres as the cpu backend, bit for bit (the determinism contract, docs/kernels.md).
// BM_View/cpu/disparity_window: the cpu's with stereo's disparity window (its outcome
// checked against the truth only). BM_View/<backend>/guided_stereo: stereo's fine pass by
// the guided kernels on that backend (the cpu's checked against the truth, the others
// against the cpu's bit for bit). Counters: each stage's milliseconds (of_which_stereo_ms
// is part of perception_ms, planning_<stage>_ms of planning_ms). Not in it: the arm's
// obstacle update and goal checks (the arm's work, BM_MotionPlan), and later sampling rounds
// when round 0 ranks nothing worth a move.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_common.h"
#include "fvp/accel/backend.h"
#include "fvp/accel/backend_choice.h"
#include "fvp/host/eval/fruitlet_matching.h"
#include "fvp/host/nbv/cluster_completion.h"
#include "fvp/host/nbv/loop_clock.h"
#include "fvp/host/nbv/nbv_setup.h"
#include "fvp/host/nbv/sizing_guidance.h"
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
    // Where a tour would first look; the views themselves are the orbit's.
    out.target.T_world_start_camera = out.world.startCameraPose();
    out.target.center_m = out.world.clusterCenter_m();
    return out;
  }();
  return w;
}

/// What the timed view gave, and each stage's wall time.
struct ViewOutcome {
  double perception_s = 0, stereo_s = 0, mapping_s = 0, tsdf_s = 0, session_other_s = 0;
  double sizing_s = 0, guidance_s = 0, planning_s = 0;
  std::map<std::string, double> planning_stages_s;  ///< PlanStep::timings_s by name
  std::optional<Eigen::Isometry3d> best_view;
  std::vector<double> sizes_mm;
  std::vector<Eigen::Vector3d> centers_m;
  std::uint64_t device_waits = 0;  ///< Backend::deviceWaits() over the view
  void addTimes(const ViewOutcome& o) {
    perception_s += o.perception_s;
    stereo_s += o.stereo_s;
    mapping_s += o.mapping_s;
    tsdf_s += o.tsdf_s;
    session_other_s += o.session_other_s;
    sizing_s += o.sizing_s;
    guidance_s += o.guidance_s;
    planning_s += o.planning_s;
    device_waits += o.device_waits;
    for (const auto& [name, seconds] : o.planning_stages_s) planning_stages_s[name] += seconds;
  }
  /// Stereo matching is part of perception, so it is not added again.
  double total_s() const {
    return perception_s + mapping_s + tsdf_s + session_other_s + sizing_s + guidance_s + planning_s;
  }
};

/// A cluster's loop without the arm: the session and planner of the setup, and the automatic
/// stop's sizing and guidance as NbvSetup::runCluster attaches them.
struct ViewLoop {
  std::unique_ptr<ClusterWork> work;
  host::nbv::SteadyLoopClock clock;
  std::optional<host::nbv::ClusterCompletion> completion;
  std::optional<host::nbv::SizingGuidance> guidance;
  const accel::Backend* backend;

  ViewLoop(NbvSetup& setup, const NbvSetupOptions& options)
      : work(setup.makeWork(workload().target)), backend(setup.backend()) {
    completion.emplace(*work->session, clock, options.sizing, options.stop.completion);
    guidance.emplace(*completion, *work->planner, options.sizing.well_seen_fraction);
  }

  /// One view as the loop takes it: mapped, sized, guidance given, then one sampling round
  /// from where it was taken, every candidate reachable (the arm's filter is the arm's work).
  ViewOutcome take(int index) {
    const host::StereoFrame& frame = workload().frames[static_cast<std::size_t>(index)];
    ViewOutcome out;
    const std::uint64_t waits_before = backend ? backend->deviceWaits() : 0;
    const auto t_view = Clock::now();
    const host::ViewResult view = work->session->addView(frame);
    const double add_view_s = secondsSince(t_view);
    if (!work->session->map()) return out;  // no tag yet: the view waits for the region
    out.perception_s = view.perceive_s;
    out.stereo_s = view.perception.sgbm_s;
    out.mapping_s = view.scan.seconds;
    out.tsdf_s = view.tsdf_s;
    out.session_other_s =
        std::max(0.0, add_view_s - view.perceive_s - view.scan.seconds - view.tsdf_s);
    const host::nbv::ViewEvent event{index, frame.T_world_camera, &frame, &view, clock.now_s()};
    const auto t_size = Clock::now();
    completion->onView(event);
    out.sizing_s = secondsSince(t_size);
    const auto t_guide = Clock::now();
    guidance->onView(event);
    out.guidance_s = secondsSince(t_guide);
    host::planner::PlanStep step;
    const auto all = [](const Eigen::Isometry3d&) { return true; };
    const auto t_plan = Clock::now();
    const auto ranking =
        work->planner->rank(*work->session->map(), frame.T_world_camera, all, 0, step);
    out.planning_s = secondsSince(t_plan);
    for (const auto& [name, seconds] : step.timings_s) out.planning_stages_s[name] += seconds;
    if (ranking && !ranking->order.empty())
      out.best_view = ranking->candidates[ranking->order.front()].T_world_camera;
    if (backend) out.device_waits = backend->deviceWaits() - waits_before;
    for (const host::nbv::FruitletSnapshot& f : completion->history().back().fruitlets) {
      out.sizes_mm.push_back(f.size_mm);
      out.centers_m.push_back(f.center_m);
    }
    return out;
  }
};

/// A fresh cluster through the first kViews - 1 views, untimed, then the last one timed.
ViewOutcome runView(NbvSetup& setup, const NbvSetupOptions& options) {
  ViewLoop loop(setup, options);
  for (int v = 0; v + 1 < kViews; ++v) loop.take(v);
  // The timed view must be one view's work, not the region's first (which maps every view).
  if (!loop.work->session->map()) throw std::runtime_error("no early view showed the tag");
  return loop.take(kViews - 1);
}

NbvSetupOptions optionsFor(accel::BackendKind kind) {
  NbvSetupOptions options;
  options.backend = *accel::parseBackendChoice(accel::toString(kind));  // the same names
  return options;
}

/// Every world fruitlet matched to a sized one as the trials score them (one to one,
/// eval::matchFruitlets), the sized centre inside the fruitlet and its size within
/// kSizeToleranceMm of the truth (empty: so).
std::string checkAgainstTruth(const ViewOutcome& cpu) {
  const std::vector<robot::sim::Fruitlet>& truth = workload().world.fruitlets();
  std::vector<Eigen::Vector3d> truth_centers_m;
  for (const robot::sim::Fruitlet& f : truth) truth_centers_m.push_back(f.center_m);
  const std::vector<int> match = host::eval::matchFruitlets(cpu.centers_m, truth_centers_m);
  for (std::size_t g = 0; g < truth.size(); ++g) {
    const int d = match[g];
    if (d < 0 || (cpu.centers_m[d] - truth[g].center_m).norm() >= truth[g].radius_m ||
        std::abs(cpu.sizes_mm[d] - truth[g].gtSizeMm()) > kSizeToleranceMm)
      return "fruitlet " + std::to_string(truth[g].index) + " not sized within " +
             std::to_string(kSizeToleranceMm) + " mm";
  }
  return {};
}

/// The cpu backend's outcome, the reference every backend must repeat.
/// How stereo's full-resolution pass runs in a BM_View variant.
enum class FinePass { kSgbm, kSgbmWindow, kGuided };

NbvSetupOptions optionsFor(accel::BackendKind kind, FinePass fine) {
  NbvSetupOptions options = optionsFor(kind);
  options.disparity_window = fine == FinePass::kSgbmWindow;
  options.guided_stereo = fine == FinePass::kGuided;
  return options;
}

/// The cpu backend's outcome with SGBM's fine pass, or with the guided kernels'.
const ViewOutcome& cpuReference(bool guided) {
  static const auto run = [](bool g) {
    const NbvSetupOptions options =
        optionsFor(accel::BackendKind::kCpu, g ? FinePass::kGuided : FinePass::kSgbm);
    NbvSetup setup(options);
    return runView(setup, options);
  };
  static const ViewOutcome sgbm = run(false);
  if (!guided) return sgbm;
  static const ViewOutcome guided_outcome = run(true);
  return guided_outcome;
}

bool sameOutcome(const ViewOutcome& a, const ViewOutcome& b) {
  return a.best_view && b.best_view && a.best_view->matrix() == b.best_view->matrix() &&
         a.sizes_mm == b.sizes_mm && a.centers_m == b.centers_m;
}

/// The stages' sums over the iterations, as per-view milliseconds counters.
void reportStages(benchmark::State& state, const ViewOutcome& sum, std::size_t fruitlets) {
  const double ms_per_view = 1e3 / double(state.iterations());
  state.counters["perception_ms"] = sum.perception_s * ms_per_view;
  state.counters["of_which_stereo_ms"] = sum.stereo_s * ms_per_view;
  state.counters["mapping_ms"] = sum.mapping_s * ms_per_view;
  state.counters["tsdf_ms"] = sum.tsdf_s * ms_per_view;
  state.counters["session_other_ms"] = sum.session_other_s * ms_per_view;
  state.counters["sizing_ms"] = sum.sizing_s * ms_per_view;
  state.counters["guidance_ms"] = sum.guidance_s * ms_per_view;
  state.counters["planning_ms"] = sum.planning_s * ms_per_view;
  for (const auto& [name, seconds] : sum.planning_stages_s)
    state.counters["planning_" + name + "_ms"] = seconds * ms_per_view;
  state.counters["fruitlets_sized"] = double(fruitlets);
  // Host waits for the device (fvp/accel/backend.h): a submission and its wait cost
  // ~0.3-0.5 ms on an H100, so this times that is the view's share of them there.
  state.counters["device_waits"] = double(sum.device_waits) / double(state.iterations());
}

// kSgbmWindow: stereo's fine pass over the Cluster Region's disparities and nearer
// (NbvSetupOptions::disparity_window): its own outcome, checked against the truth, since
// its disparities are not the whole range's. kGuided: the guided kernels' fine pass
// (NbvSetupOptions::guided_stereo), checked against the truth on the cpu and bit for bit
// against the cpu's on the other backends.
void BM_View(benchmark::State& state, accel::BackendKind kind, FinePass fine) {
  try {
    const NbvSetupOptions options = optionsFor(kind, fine);
    NbvSetup setup(options);  // an unavailable backend throws here: skipped with its reason
    const ViewOutcome& reference = cpuReference(fine == FinePass::kGuided);
    if (const std::string wrong = checkAgainstTruth(reference); !wrong.empty())
      throw std::runtime_error("cpu reference: " + wrong);
    const bool disparity_window = fine == FinePass::kSgbmWindow;
    ViewOutcome sum;
    bool same = true;
    for (auto _ : state) {
      const ViewOutcome view = runView(setup, options);
      state.SetIterationTime(view.total_s());
      if (disparity_window) {
        if (const std::string wrong = checkAgainstTruth(view); !wrong.empty())
          throw std::runtime_error("with the disparity window: " + wrong);
      } else {
        same = same && sameOutcome(view, reference);
      }
      sum.addTimes(view);
    }
    if (!same) throw std::runtime_error("the best view or the sizes differ from the cpu's");
    reportStages(state, sum, reference.sizes_mm.size());
  } catch (const std::exception& e) {
    state.SkipWithError((std::string("BM_View: ") + e.what()).c_str());
  }
}

void registerView(const std::string& name, accel::BackendKind kind, FinePass fine) {
  benchmark::RegisterBenchmark(name.c_str(), BM_View, kind, fine)
      ->Iterations(5)
      ->UseManualTime()
      ->Unit(benchmark::kMillisecond);
}

void registerAll() {
  for (accel::BackendKind kind :
       {accel::BackendKind::kCpu, accel::BackendKind::kOpenCl, accel::BackendKind::kVulkan}) {
    const std::string name = "BM_View/" + std::string(accel::toString(kind));
    registerView(name, kind, FinePass::kSgbm);
    registerView(name + "/guided_stereo", kind, FinePass::kGuided);
  }
  registerView("BM_View/cpu/disparity_window", accel::BackendKind::kCpu, FinePass::kSgbmWindow);
}

const bool kRegistered = (registerAll(), true);

}  // namespace
}  // namespace fvp::bench
