// A trial's report for a person, written from its result.json: report.md (one-cluster and
// tree trials), its figures (the camera path, sizes against truth), result.json itself with
// the coarse map beside it, and the views' small pictures. Apart from TrialParts, which
// computes what these write.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fvp/host/map/map_engine.h"
#include "fvp/host/perception/stereo_frame.h"
#include "fvp/robot/sim/world.h"

namespace fvp::trials {

/// Writes an extra (a map, a cloud, the report, the view images) after result.json: the
/// caller's writer turns a failure into a warning naming `file`, so the result stands.
using ExtraWriter =
    std::function<void(const std::string& file, const std::function<void()>& write)>;

/// Which figures a trial's report shows (drawn into its directory beside report.md).
struct ReportFigures {
  bool path = false;   ///< path.png: the camera path
  bool sizes = false;  ///< sizes.png: estimated against true sizes
};

/// A Cluster Region drawn on the camera-path figure.
struct PathRegion {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
};

/// result.json first (nothing after it, a full disk or a missing gnuplot, can lose it), then
/// the coarse map and the figures: path.png (with the regions) and sizes.png (left out,
/// without a warning, when no fruitlet matched). A figure that cannot be drawn becomes a
/// warning in result (written again). Returns the figures drawn.
ReportFigures writeResultMapAndPath(
    nlohmann::json& result, const robot::sim::World& world, const host::map::MapEngine* map,
    const std::vector<Eigen::Vector3d>& camera_path, const std::vector<PathRegion>& regions,
    const std::string& region_title, const std::filesystem::path& out_dir,
    const std::function<void(const std::string&)>& warn, const ExtraWriter& extra);

/// A tree trial's files into out_dir, each atomically: result.json first, then the shared
/// coarse map (coarse.bt, when a cluster was mapped), the camera path over the tree and
/// report.md. The clusters' own files were written as each was finished (cluster_K/).
void writeTreeOutputs(nlohmann::json& result, const robot::sim::World& world,
                      const host::map::MapEngine* map,
                      const std::vector<Eigen::Vector3d>& camera_path,
                      const std::filesystem::path& out_dir,
                      const std::function<void(const std::string&)>& warn,
                      const ExtraWriter& extra);

/// The simulated seconds a clock's record (result["clock"]) charged, by stage ("capture_s",
/// "motion_s", ...), summed over its iterations: the wall times the iterations also record
/// and their "total_s" left out. Empty for a record without iterations.
std::map<std::string, double> simulatedSecondsByStage(const nlohmann::json& clock);

/// The view's left image as the small PNG of the report (views/NNN.png), encoded: kept in
/// memory during the loop and written after result.json, so a full disk cannot cost the trial.
std::string encodeViewImage(int index, const host::StereoFrame& frame);

/// report.md of a one-cluster trial, from its result.json (what writeOutputs writes).
std::string trialReportMarkdown(const nlohmann::json& result, const ReportFigures& figures);
/// report.md of a tree trial, from its result.json (what writeTreeOutputs writes).
std::string treeReportMarkdown(const nlohmann::json& result, const ReportFigures& figures);

/// The gnuplot script of path.png: top and side views of the camera positions (path, in
/// capture order, coloured by it), each view's viewing direction from result["view_log"]
/// as a 3 cm arrow, the start and last views marked, the fruitlets and the regions.
std::string cameraPathScript(const std::vector<Eigen::Vector3d>& fruitlets,
                             const std::vector<Eigen::Vector3d>& path, const nlohmann::json& result,
                             const std::vector<PathRegion>& regions,
                             const std::string& region_title);
/// sizes.png: our estimator's size against the true size of each matched fruitlet (one
/// colour a cluster in a tree), with y = x and a +-0.5 mm band. False, and no file, when
/// no fruitlet matched; std::runtime_error when gnuplot cannot draw it.
bool plotSizeScatter(const nlohmann::json& result, const std::filesystem::path& png);

}  // namespace fvp::trials
