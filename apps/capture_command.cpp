// `fvp capture`: render one view of a simulated world, run the perception chain on it and
// write it in the capture format (docs/capture-format.md).
#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/host/core/input_checks.h"
#include "fvp/host/core/interrupt.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/perception/capture.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/object_ids.h"
#include "fvp/robot/sim/occlusion_statistic.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"
#include "stereo_bag_files.h"

namespace fvp::apps {
namespace {

// How far a --pose quaternion's norm may be from 1: rounding as people type rotations
// (0.707 for 1/sqrt 2 is off by 3e-4), not a typo's missing or doubled component.
constexpr double kQuaternionNormTolerance = 0.01;

// "x,y,z,qx,qy,qz,qw" -> the left camera's optical-frame pose in the world.
Eigen::Isometry3d parsePose(const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    // Decimal text, as every number fvp reads (stod alone takes " 5", hex and inf).
    const double x =
        host::isDecimalNumberText(item, false) ? std::strtod(item.c_str(), nullptr) : std::nan("");
    if (!std::isfinite(x))
      throw std::invalid_argument("--pose: '" + item.substr(0, 40) + "' is not a finite number");
    v.push_back(x);
  }
  if (v.size() != 7)
    throw std::invalid_argument("--pose: expected 7 comma-separated numbers x,y,z,qx,qy,qz,qw");
  // A unit quaternion as typed (rounded): its norm within kQuaternionNormTolerance of 1. A
  // component beyond 2 is checked first, so the norm cannot overflow (1e308 normalised to
  // an identity rotation).
  Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  const bool bounded = q.coeffs().cwiseAbs().maxCoeff() <= 2.0;
  if (!bounded || std::abs(q.norm() - 1.0) > kQuaternionNormTolerance) {
    std::ostringstream norm;
    norm << (bounded ? q.norm() : q.coeffs().cwiseAbs().maxCoeff());
    throw std::invalid_argument(
        "--pose: field 'qx,qy,qz,qw': expected a unit quaternion (norm within " +
        std::to_string(kQuaternionNormTolerance).substr(0, 4) + " of 1), got " +
        (bounded ? "norm " : "a component of ") + norm.str());
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  host::checkPose(T, "--pose", "x,y,z");
  return T;
}

std::string vec(const Eigen::Vector3d& p) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(4) << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return os.str();
}

/// What `fvp capture` stores of one rendered, perceived view (docs/capture-format.md).
[[maybe_unused]] host::Capture captureOf(const host::StereoFrame& frame,
                                         const host::PerceptionResult& result,
                                         const robot::sim::World& world) {
  host::Capture capture;
  capture.left_bgr = frame.left_bgr;
  capture.right_bgr = frame.right_bgr;
  capture.intrinsics = frame.intrinsics;
  capture.T_world_camera = frame.T_world_camera;
  capture.disparity_px = result.disparity.disparity_px;
  capture.fruitlet_mask = result.fruitlet_mask;
  capture.roi_points_m = result.clouds.roi_points_m;
  capture.other_points_m = result.clouds.other_points_m;
  capture.has_clouds = true;
  capture.ground_truth_json = world.groundTruthJson();
  return capture;
}

}  // namespace

// A single view written into a capture set would leave a camera.yaml beside its views, and
// fvp size would refuse the set: refused before anything is rendered or written.
static void refuseCaptureSet(const std::filesystem::path& out) {
  for (const auto& entry : std::filesystem::directory_iterator(out))
    if (entry.is_directory() && std::filesystem::exists(entry.path() / "camera.yaml"))
      throw std::runtime_error("--out '" + out.string() + "' holds a capture set (" +
                               entry.path().filename().string() +
                               "/camera.yaml): a single view there would hide its views from "
                               "fvp size; write it to a new directory, or use --views");
}

// K views orbiting the cluster, each rendered, perceived and written as out/NNN.
static void writeCaptureSet(std::uint64_t seed, const std::string& world_file, int views,
                            double arc_deg, const std::filesystem::path& out) {
  // A set written over an older one would leave its extra views behind, and fvp size would
  // mix the two worlds.
  for (const auto& entry : std::filesystem::directory_iterator(out))
    if (std::filesystem::exists(entry.path() / "camera.yaml") ||
        entry.path().filename() == "camera.yaml")
      throw std::runtime_error("--out '" + out.string() + "' already holds captures (" +
                               entry.path().filename().string() +
                               "): write the set to a new or empty directory");
  const robot::sim::WorldConfig world_config =
      world_file.empty() ? robot::sim::WorldConfig{}
                         : robot::sim::WorldConfig::fromYamlFile(world_file);
  const auto world = robot::sim::World::generate(world_config, seed);
  robot::sim::RenderConfig render = robot::sim::renderConfigFor(world_config, {}, seed);
  render.noise_seed = seed;
  robot::sim::StereoRenderer renderer(world, render);
  host::PerceptionConfig config;
  config.tag.tag_id = world.tag().tag_id;
  config.tag.tag_size_m = world.tag().tag_size_m;
  const host::PerceptionPipeline pipeline(config);
  std::optional<host::ClusterRegion> region;
  const auto poses = robot::sim::orbitViews(world, views, arc_deg);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    host::throwIfInterrupted();  // the views written so far are complete captures
    const host::StereoFrame frame = renderer.render(poses[i]);
    const host::PerceptionResult result = pipeline.process(frame, region);
    if (!region && result.region) region = result.region;
    const host::Capture capture = captureOf(frame, result, world);
    char name[24];  // any size_t in %03zu fits
    std::snprintf(name, sizeof(name), "%03zu", i);
    host::writeCapture(out / name, capture);
    std::cout << "view " << name << ": tag " << (result.tag ? "seen" : "not seen") << ", "
              << result.clouds.roi_points_m.size() << " ROI points -> " << (out / name).string()
              << "\n";
  }
}

namespace {

/// `fvp capture`'s options.
struct CaptureCommandOptions {
  std::uint64_t seed = 1;
  std::string world_file;
  std::string pose;
  std::string out;
  std::string bag;  ///< also the set as a ROS bag
  int views = 1;
  double arc_deg = 90.0;
};

// What the tag detection and the Cluster Region came to, against the world's ground truth.
void printTagAndRegion(const robot::sim::World& world, const host::PerceptionResult& result,
                       const host::PerceptionConfig& config) {
  const host::PerceptionStats& st = result.clouds.stats;
  if (result.tag) {
    const auto& tag = *result.tag;
    const Eigen::Isometry3d& gt = world.tag().T_world_tag;
    std::cout << std::setprecision(2) << "tag            detected id " << tag.tag_id << " (hamming "
              << tag.hamming << ", margin " << tag.decision_margin << "), error vs ground truth "
              << (tag.T_world_tag.translation() - gt.translation()).norm() * 1e3 << " mm, "
              << Eigen::AngleAxisd(tag.T_world_tag.linear().transpose() * gt.linear()).angle() *
                     180.0 / M_PI
              << " deg, in " << st.tag_s * 1e3 << " ms\n";
  } else {
    std::cout << "tag            NOT detected (id " << config.tag.tag_id
              << "): no Cluster Region; full resolution only around segmented fruitlets\n";
  }
  if (result.region)
    std::cout << std::setprecision(3) << "cluster region centre " << vec(result.region->center_m())
              << ", radius " << result.region->radius_m() << " m; true cluster centre "
              << (world.clusterCenter_m() - result.region->center_m()).norm() * 1e3
              << " mm from it\n";
}

// The stereo matcher's, the segmentation's and the point clouds' numbers.
void printPerceptionStats(const host::PerceptionResult& result) {
  const host::PerceptionStats& st = result.clouds.stats;
  const cv::Rect fine = result.disparity.fine_rect;
  std::cout << std::setprecision(1) << "SGBM           " << st.sgbm_s * 1e3
            << " ms (full resolution " << fine.width << "x" << fine.height << " px at (" << fine.x
            << ", " << fine.y << "), 1/" << result.disparity.coarse_scale
            << " resolution elsewhere)\n"
            << "segmentation   " << cv::countNonZero(result.fruitlet_mask) << " fruitlet px in "
            << st.segmentation_s * 1e3 << " ms\n"
            << "points         " << st.roi_points << " ROI, " << st.other_points << " other\n"
            << "disparities    " << st.fine_samples << " full-res + " << st.coarse_samples
            << " coarse samples; dropped " << st.droppedDisparities() << ": SGBM invalid "
            << st.sgbm_invalid << ", saturated (too near) " << st.saturated << ", blind left band "
            << st.blind_band << ", dark (no signal) " << st.no_signal << ", non-finite "
            << st.nonfinite << ", zero/negative " << st.nonpositive << ", out of range "
            << st.out_of_range << "\n";
}

// Unused in the parse-only build of the CLI fuzz harness (FVP_ON_RUN).
[[maybe_unused]] void runCaptureCommand(const CaptureCommandOptions* opt) {
  host::prepareOutputDirectory(opt->out, "--out");
  const host::OutputDirectoryLock lock(opt->out, "--out");
  if (opt->views == 1) refuseCaptureSet(opt->out);
  if (opt->views > 1) {
    if (!opt->pose.empty()) throw std::invalid_argument("--pose and --views exclude each other");
    writeCaptureSet(opt->seed, opt->world_file, opt->views, opt->arc_deg, opt->out);
    if (!opt->bag.empty()) {
      writeCaptureSetAsBag(opt->out, opt->bag);
      std::cout << "bag -> " << opt->bag << "\n";
    }
    return;
  }
  const robot::sim::WorldConfig world_config =
      opt->world_file.empty() ? robot::sim::WorldConfig{}
                              : robot::sim::WorldConfig::fromYamlFile(opt->world_file);
  const auto world = robot::sim::World::generate(world_config, opt->seed);
  const Eigen::Isometry3d T_world_camera =
      opt->pose.empty() ? world.startCameraPose() : parsePose(opt->pose);

  robot::sim::StereoRenderer renderer(world);
  const robot::sim::RenderedView view = renderer.renderWithGroundTruth(T_world_camera);
  const host::StereoFrame& frame = view.frame;
  const double render_s = renderer.lastRenderSeconds();
  robot::sim::RenderOptions no_leaves;  // ids only: for the occlusion statistic
  no_leaves.with_leaves = false;
  no_leaves.images = false;
  const robot::sim::RenderedView bare = renderer.renderWithGroundTruth(T_world_camera, no_leaves);
  const double bare_render_s = renderer.lastRenderSeconds();

  host::PerceptionConfig config;
  config.tag.tag_id = world.tag().tag_id;
  config.tag.tag_size_m = world.tag().tag_size_m;
  const host::PerceptionPipeline pipeline(config);
  const host::PerceptionResult result = pipeline.process(frame);

  host::writeCapture(opt->out, captureOf(frame, result, world));

  const auto occlusion = robot::sim::OcclusionStatistic::compute(view.ground_truth.object_id,
                                                                 bare.ground_truth.object_id);
  const auto& K = frame.intrinsics;
  std::cout << std::fixed << std::setprecision(1);
  std::cout << "world          seed " << world.seed() << ": " << world.fruitlets().size()
            << " fruitlets, " << world.leaves().size() << " leaves, tag36h11 id "
            << world.tag().tag_id << "\n"
            << "camera         " << K.width_px << "x" << K.height_px << " at "
            << vec(T_world_camera.translation()) << (opt->pose.empty() ? " (start view)" : "")
            << "\n"
            << "render         " << render_s * 1e3 << " ms per pair (+ " << bare_render_s * 1e3
            << " ms for the leafless render of the occlusion statistic)\n";
  printTagAndRegion(world, result, config);
  printPerceptionStats(result);
  std::cout << std::setprecision(3)
            << "occlusion      visible fraction of each fruitlet's "
               "silhouette vs a render without leaves:\n";
  for (const auto& f : occlusion.fruitlets())
    std::cout << "  fruitlet " << f.object_id - robot::sim::kFirstFruitletId << "   "
              << (f.unoccluded_px > 0 ? std::to_string(f.visible_fraction).substr(0, 5)
                                      : std::string("out of view"))
              << "  (" << f.visible_px << " of " << f.unoccluded_px << " px)\n";
  std::cout << "  mean         " << occlusion.meanVisibleFraction() << " over "
            << occlusion.fruitletsInView() << " fruitlets in view\n"
            << "capture        " << opt->out << "\n";
}

}  // namespace

void addCaptureCommand(CLI::App& app) {
  auto opt = optionStorage<CaptureCommandOptions>();
  auto* cmd = app.add_subcommand(
      "capture",
      "Render one view of a simulated world (default: the start view), run the "
      "perception chain and write it in the capture format (docs/capture-format.md)");
  cmd->add_option("--seed", opt->seed, "world seed")->check(decimalUnsigned())->required();
  cmd->add_option("--world", opt->world_file, "world config YAML (default: built-in defaults)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--pose", opt->pose,
                  "left camera pose in the world, x,y,z,qx,qy,qz,qw (optical frame: x right, "
                  "y down, z forward; default: the world's start view)");
  cmd->add_option("--views", opt->views,
                  "write a set of this many views orbiting the cluster as --out/000, 001, ... "
                  "(for fvp size)")
      ->check(decimalUnsigned())
      ->check(CLI::Range(1, 360))
      ->capture_default_str();
  cmd->add_option("--arc-deg", opt->arc_deg, "arc the --views span around the cluster")
      ->check(finiteNumber())
      ->check(CLI::Range(0.0, 360.0))
      ->capture_default_str();
  cmd->add_option("--out", opt->out, "capture directory (created)")
      ->required()
      ->check(nonEmptyPath());
  cmd->add_option("--bag", opt->bag,
                  "also write the --views set as this ROS bag: stereo pairs, camera infos and tf "
                  "(docs/ros.md)")
      ->check(nonEmptyPath());
  FVP_ON_RUN(cmd, [opt] {
    if (!opt->bag.empty() && opt->views < 2)
      throw std::invalid_argument("--bag: expected a set (--views 2 or more)");
    runCaptureCommand(opt.get());
  });
}

}  // namespace fvp::apps
