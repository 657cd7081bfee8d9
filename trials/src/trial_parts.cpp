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

WorkspaceTree loadWorkspaceTree(const ArmModel& arm,
                                const std::function<void(const std::string&)>& warn) {
  std::ostringstream log;
  WorkspaceTree tree = WorkspaceTree::loadOrBuild(arm, log);
  std::istringstream lines(log.str());
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("warning: ", 0) == 0) warn(line.substr(9));
  return tree;
}

TrialParts::TrialParts(const TrialOptions& options, const std::string& engine,
                       const host::nbv::ClusterWork& work)
    : options_(options), engine_(engine), work_(work) {}

nlohmann::json TrialParts::configJson(const host::sizing::SizingConfig& sizing_config) const {
  return {{"engine", engine_},
          {"clock", robot::sim::SimClock::modeName(options_.clock)},
          {"fine_map_extent", host::map::toString(work_.map_config.fine_map_extent)},
          {"stop", host::nbv::toString(options_.stop)},
          {"sizing",
           {{"estimator", host::sizing::toString(sizing_config.estimator)},
            {"min_support_area_fraction", sizing_config.min_support_area_fraction},
            {"sphere_fit_support_area_fraction", sizing_config.sphere_fit_support_area_fraction},
            {"max_detection_overlap_fraction", sizing_config.max_detection_overlap_fraction},
            {"view_agreement_disparity_px", sizing_config.view_agreement_disparity_px},
            {"min_view_agreement_registered", sizing_config.min_view_agreement_registered}}}};
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
  if (const host::map::MapEngine* map = session().map())
    extra("fine.ot", [&] { map->exportFine(dir / "fine.ot"); });
  const auto& sz = sizing_;
  extra("surface.ply",
        [&] { host::writePlyPoints(dir / "surface.ply", session().surfacePoints()); });
  extra("mesh.ply", [&] {
    const host::tsdf::TriangleMesh mesh = session().surfaceMesh();
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
  if (const auto& region = session().region())
    regions.push_back({region->center_m(), region->radius_m()});
  const ReportFigures figures = writeResultMapAndPath(
      result, world, session().map(), camera_path, regions, "Cluster Region", out_dir, warn, extra);
  writeClusterFiles(out_dir, extra);
  extra("report.md", [&] {
    host::writeFileAtomically(out_dir / "report.md", "trial report",
                              trialReportMarkdown(result, figures));
  });
}

}  // namespace fvp::trials

namespace fvp::trials {

nlohmann::json TrialParts::score(host::sizing::SizingResult sizing,
                                 host::sizing::SizingEstimator estimator, const World& world,
                                 const std::vector<int>& fruitlet_indices,
                                 const std::optional<Eigen::Isometry3d>& T_world_tag_true) {
  sizing_ = std::move(sizing);
  const std::vector<host::eval::GroundTruthFruitlet> truth = groundTruthOf(world, fruitlet_indices);
  nlohmann::json out = host::eval::scoreBothEstimators(sizing_, truth, estimator);
  if (T_world_tag_true) {
    // Each detection's centre in the seen tag's frame (the maps' frame, as addTagFrame
    // reports it), put in the world through the true tag; with no tag seen, nothing placed.
    host::sizing::SizingResult in_tag_frame = sizing_;
    if (const auto& T_seen = session().T_world_tag()) {
      const Eigen::Isometry3d via_tag = *T_world_tag_true * T_seen->inverse() *
                                        Eigen::Translation3d(-session().appliedAnchorShift_m());
      for (auto& f : in_tag_frame.fruitlets) {
        f.center_m = via_tag * f.center_m;
        f.sphere_center_m = via_tag * f.sphere_center_m;
        f.centroid_m = via_tag * f.centroid_m;
      }
    } else {
      in_tag_frame.fruitlets.clear();
    }
    const nlohmann::json scored = host::eval::scoreSizing(in_tag_frame, truth, estimator);
    out["fruitlets_tag_frame"] = scored.at("fruitlets");
    out["metrics_tag_frame"] = scored.at("metrics");
  }
  // The details object must outlive the loop (items() of a temporary would dangle).
  nlohmann::json details = host::eval::sizingDetails(sizing_);
  host::eval::addTagFrame(details, session().T_world_tag(), session().appliedAnchorShift_m());
  for (const auto& [key, value] : details.items()) out[key] = value;
  // No TSDF when no view ever saw the tag (nothing was sized then).
  const host::tsdf::TsdfVolume* tsdf = session().tsdf();
  out["sizing_stats"]["tsdf_blocks"] = tsdf ? tsdf->blockCount() : 0;
  out["sizing_stats"]["tsdf_bytes"] = tsdf ? tsdf->memoryBytes() : 0;
  out["sizing_stats"]["tsdf_bytes_per_block"] =
      tsdf && tsdf->blockCount() ? double(tsdf->memoryBytes()) / tsdf->blockCount() : 0.0;
  return out;
}

}  // namespace fvp::trials
