#include "trial_parts.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "fvp/accel/backend.h"
#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/cluster_region.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/eval/sizing_score.h"
#include "fvp/host/map/map_config.h"
#include "fvp/host/perception/ply_io.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/host/sizing/fruitlet_sizer.h"
#include "fvp/host/tsdf/tsdf_volume.h"

namespace fvp::trials {
// The simulator's parts and the arm, by their short names.
using namespace fvp::robot;
using namespace fvp::robot::sim;

std::string defaultEngine(const std::string& planner) {
  return host::planner::PlannerRegistry::instance().at(planner).default_engine;
}

std::string defaultCacheDir() {
  if (const char* dir = std::getenv("FVP_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return (std::filesystem::path(xdg) / "fvp").string();
  if (const char* home = std::getenv("HOME"); home && *home)
    return (std::filesystem::path(home) / ".cache" / "fvp").string();
  return (std::filesystem::temp_directory_path() / "fvp-cache").string();
}

WorkspaceTree loadWorkspaceTree(const ArmModel& arm,
                                const std::function<void(const std::string&)>& warn) {
  std::ostringstream log;
  WorkspaceTree tree = WorkspaceTree::loadOrBuild(arm, log);
  std::istringstream lines(log.str());
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("warning: ", 0) == 0) warn(line.substr(9));
  return tree;
}

struct TrialParts::Impl {
  Impl(const TrialOptions& options, const std::string& engine, accel::Backend* backend,
       const host::PerceptionConfig& perception, std::uint64_t planner_seed)
      : options(options),
        engine(engine),
        backend(backend),
        map_config(host::planner::plannerMapConfig(options.planner, engine)),
        session(perception, engine, map_config, backend) {
    session.enableTsdf();
    if (options.register_views) session.enableViewRegistration();
    planner = host::planner::createPlanner(options.planner, options.planner_config, planner_seed,
                                           backend);
  }

  TrialOptions options;
  std::string engine;
  accel::Backend* backend;
  host::map::MapConfig map_config;  ///< the maps' config, as the session got it
  host::MappingSession session;
  std::unique_ptr<host::planner::ViewPlanner> planner;
  host::sizing::SizingConfig sizing_config;
  host::sizing::SizingResult sizing;  ///< of the last sizeAndScore
};

TrialParts::TrialParts(const TrialOptions& options, const std::string& engine,
                       accel::Backend* backend, const host::PerceptionConfig& perception,
                       std::uint64_t planner_seed)
    : impl_(std::make_unique<Impl>(options, engine, backend, perception, planner_seed)) {}

TrialParts::~TrialParts() = default;

ViewOutcome TrialParts::addView(const host::StereoFrame& frame) {
  ViewOutcome outcome;
  outcome.result = impl_->session.addView(frame);
  outcome.mapping_s = outcome.result.scan.seconds;
  outcome.tsdf_s = outcome.result.tsdf_s;
  return outcome;
}

host::map::MapEngine* TrialParts::map() {
  return impl_->session.map();
}

host::MappingSession& TrialParts::session() {
  return impl_->session;
}

const host::sizing::SizingConfig& TrialParts::sizingConfig() const {
  return impl_->sizing_config;
}

host::planner::ViewPlanner& TrialParts::planner() {
  return *impl_->planner;
}

nlohmann::json TrialParts::configJson() const {
  return {
      {"engine", impl_->engine},
      {"clock", impl_->options.clock},
      {"fine_map_extent", host::map::toString(impl_->map_config.fine_map_extent)},
      {"stop", impl_->options.stop},
      {"sizing",
       {{"estimator", host::sizing::toString(impl_->sizing_config.estimator)},
        {"min_support_area_fraction", impl_->sizing_config.min_support_area_fraction},
        {"sphere_fit_support_area_fraction", impl_->sizing_config.sphere_fit_support_area_fraction},
        {"max_detection_overlap_fraction", impl_->sizing_config.max_detection_overlap_fraction},
        {"view_agreement_disparity_px", impl_->sizing_config.view_agreement_disparity_px}}}};
}

std::vector<host::eval::GroundTruthFruitlet> groundTruthOf(const World& world,
                                                           const std::vector<int>& indices) {
  std::vector<host::eval::GroundTruthFruitlet> truth;
  for (const int i : indices) {
    const Fruitlet& f = world.fruitlets().at(static_cast<std::size_t>(i));
    truth.push_back({f.center_m, f.gtSizeMm()});
  }
  return truth;
}

const std::vector<std::string>& TrialParts::clusterFiles() {
  static const std::vector<std::string> files = {"fine.ot", "surface.ply", "mesh.ply",
                                                 "clusters.ply"};
  return files;
}

void TrialParts::writeClusterFiles(const std::filesystem::path& dir,
                                   const ExtraWriter& extra) const {
  std::error_code ignored;  // a directory that cannot be made fails each file's write below
  std::filesystem::create_directories(dir, ignored);
  if (const host::map::MapEngine* map = impl_->session.map())
    extra("fine.ot", [&] { map->exportFine(dir / "fine.ot"); });
  const auto& sz = impl_->sizing;
  extra("surface.ply",
        [&] { host::writePlyPoints(dir / "surface.ply", impl_->session.surfacePoints()); });
  extra("mesh.ply", [&] {
    const host::tsdf::TriangleMesh mesh = impl_->session.surfaceMesh();
    host::writePlyMesh(dir / "mesh.ply", mesh.vertices_m, mesh.triangles,
                       "fvp TSDF mesh (marching cubes), world frame, metres");
  });
  extra("clusters.ply", [&] {
    host::writePlyColoredPoints(dir / "clusters.ply", sz.points,
                                host::sizing::clusterColours(sz.labels),
                                "fvp clusters, world frame, metres; grey = noise");
  });
}

const std::vector<std::string>& TrialParts::outputFiles() {
  static const std::vector<std::string> files = {"result.json",  "report.md",   "coarse.bt",
                                                 "fine.ot",      "surface.ply", "mesh.ply",
                                                 "clusters.ply", "path.png",    "sizes.png"};
  return files;
}

void TrialParts::writeOutputs(nlohmann::json& result, const World& world,
                              const std::vector<Eigen::Vector3d>& camera_path,
                              const std::filesystem::path& out_dir,
                              const std::function<void(const std::string&)>& warn,
                              const ExtraWriter& extra) const {
  std::vector<PathRegion> regions;
  if (const auto& region = impl_->session.region())
    regions.push_back({region->center_m(), region->radius_m()});
  const ReportFigures figures =
      writeResultMapAndPath(result, world, impl_->session.map(), camera_path, regions,
                            "Cluster Region", out_dir, warn, extra);
  writeClusterFiles(out_dir, extra);
  extra("report.md", [&] {
    host::writeFileAtomically(out_dir / "report.md", "trial report",
                              trialReportMarkdown(result, figures));
  });
}

}  // namespace fvp::trials

namespace fvp::trials {

nlohmann::json TrialParts::sizeAndScore(const World& world,
                                        const std::vector<int>& fruitlet_indices) {
  impl_->sizing = impl_->session.sizeFruitlets(impl_->sizing_config);
  const std::vector<host::eval::GroundTruthFruitlet> truth = groundTruthOf(world, fruitlet_indices);
  nlohmann::json out =
      host::eval::scoreBothEstimators(impl_->sizing, truth, impl_->sizing_config.estimator);
  // The details object must outlive the loop (items() of a temporary would dangle).
  const nlohmann::json details = host::eval::sizingDetails(impl_->sizing);
  for (const auto& [key, value] : details.items()) out[key] = value;
  // No TSDF when no view ever saw the tag (nothing was sized then).
  const host::tsdf::TsdfVolume* tsdf = impl_->session.tsdf();
  out["sizing_stats"]["tsdf_blocks"] = tsdf ? tsdf->blockCount() : 0;
  out["sizing_stats"]["tsdf_bytes"] = tsdf ? tsdf->memoryBytes() : 0;
  out["sizing_stats"]["tsdf_bytes_per_block"] =
      tsdf && tsdf->blockCount() ? double(tsdf->memoryBytes()) / tsdf->blockCount() : 0.0;
  return out;
}

}  // namespace fvp::trials
