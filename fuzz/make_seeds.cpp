// Writes the fuzz corpus (fuzz/corpus/<name>/) with the project's own writers on small
// inputs: tiny captures, PLY clouds, configs (the committed defaults and toJson), simulated
// worlds' ground truth, a coarse .bt map, a small workspace-tree cache, trials.jsonl lines.
// Run by hand after a format changes; the outputs are committed:
//   cmake --build build --target fvp_fuzz_make_seeds && build/fuzz/fvp_fuzz_make_seeds fuzz
#include <octomap/OcTree.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "capture_container.h"
#include "fvp/host/map/map_config.h"
#include "fvp/host/map/octomap_io.h"
#include "fvp/host/perception/capture.h"
#include "fvp/host/perception/ply_io.h"
#include "fvp/host/planner/planner_config.h"
#include "fvp/host/planner/rvp_config.h"
#include "fvp/robot/arm_config.h"
#include "fvp/robot/arm_model.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/sim/world_config.h"
#include "fvp/robot/workspace_tree.h"

namespace fs = std::filesystem;
using namespace fvp;

namespace {

fs::path g_fuzz_dir;

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  if (!in) throw std::runtime_error("cannot read " + path.string());
  return s.str();
}

void put(const std::string& name, const std::string& file, const std::string& bytes) {
  const fs::path dir = g_fuzz_dir / "corpus" / name;
  fs::create_directories(dir);
  std::ofstream out(dir / file, std::ios::binary | std::ios::trunc);
  out << bytes;
  if (!out) throw std::runtime_error("cannot write " + (dir / file).string());
  std::printf("%s/%s: %zu bytes\n", name.c_str(), file.c_str(), bytes.size());
}

void copySource(const std::string& name, const std::string& file, const fs::path& from) {
  put(name, file, slurp(g_fuzz_dir / ".." / from));
}

fs::path scratch() {
  const fs::path dir = fs::temp_directory_path() / "fvp_fuzz_make_seeds";
  fs::create_directories(dir);
  return dir;
}

// A small capture with every part (or only the required ones), as one harness input.
std::string captureInput(int width, int height, bool all_parts, bool grey,
                         const std::string& ground_truth, bool instances = false) {
  host::Capture c;
  c.intrinsics.width_px = width;
  c.intrinsics.height_px = height;
  c.intrinsics.fx_px = c.intrinsics.fy_px = 20.0;
  c.intrinsics.cx_px = 0.5 * (width - 1);
  c.intrinsics.cy_px = 0.5 * (height - 1);
  c.intrinsics.baseline_m = 0.05;
  c.T_world_camera.translation() = Eigen::Vector3d(0.1, -0.4, 1.2);
  c.T_world_camera.linear() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  c.left_bgr = cv::Mat(height, width, CV_8UC3);
  c.right_bgr = cv::Mat(height, width, CV_8UC3);
  cv::randu(c.left_bgr, 0, 255);
  cv::randu(c.right_bgr, 0, 255);
  if (all_parts) {
    c.disparity_px = cv::Mat(height, width, CV_32F, cv::Scalar(3.5f));
    c.disparity_px.at<float>(0, 0) = 0.0f;
    c.fruitlet_mask = cv::Mat::zeros(height, width, CV_8U);
    c.fruitlet_mask(cv::Rect(1, 1, 3, 2)).setTo(255);
    if (instances) {  // a 16-bit instance segmentation: two touching instances
      c.fruitlet_mask = cv::Mat::zeros(height, width, CV_16U);
      c.fruitlet_mask(cv::Rect(1, 1, 2, 2)).setTo(2);
      c.fruitlet_mask(cv::Rect(3, 1, 2, 2)).setTo(40000);
    }
    c.has_clouds = true;
    c.roi_points_m = {{0.1f, 0.2f, 1.0f}, {0.11f, 0.2f, 1.01f}, {0.12f, 0.21f, 1.0f}};
    c.other_points_m = {{-0.3f, 0.0f, 0.9f}, {0.5f, 0.1f, 1.5f}};
    c.ground_truth_json = ground_truth;
  }
  const fs::path dir = scratch() / "capture";
  fs::remove_all(dir);
  host::writeCapture(dir, c);
  if (grey) {
    cv::Mat g(height, width, CV_8U);
    cv::randu(g, 0, 255);
    cv::imwrite((dir / "left.png").string(), g);
  }
  std::array<std::string, fuzz::kCaptureFiles.size()> parts;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const fs::path file = dir / fuzz::kCaptureFiles[i];
    if (fs::exists(file)) parts[i] = slurp(file);
  }
  return fuzz::joinCaptureParts(parts);
}

std::string plyFile(const std::function<void(const fs::path&)>& write) {
  const fs::path path = scratch() / "seed.ply";
  write(path);
  return slurp(path);
}

void putConfigSeeds() {
  // Configs: the committed defaults, the built-in defaults as JSON (YAML's flow form).
  copySource("world_config", "world_default.yaml", "robot/sim/config/world_default.yaml");
  copySource("world_config", "world_isolated.yaml", "robot/sim/config/world_isolated.yaml");
  copySource("world_config", "world_unoccluded.yaml", "robot/sim/config/world_unoccluded.yaml");
  put("world_config", "defaults.json", robot::sim::WorldConfig{}.toJson());
  copySource("arm_config", "arm_default.yaml", "robot/config/arm_default.yaml");
  put("arm_config", "defaults.json", robot::ArmConfig{}.toJson());
  copySource("map_config", "map_default.yaml", "host/config/map_default.yaml");
  copySource("map_config", "map_unknown_key.yaml", "tests/apps/data/map_unknown_key.yaml");
  put("map_config", "vectors.yaml",
      "observation_min_m: [-0.5, -0.5, 0.0]\nobservation_max_m: [0.5, 0.5, 1.5]\n"
      "fine_map_extent: observation_box\nprob_hit: 0.7\n");
  copySource("planner_config", "planner_default.yaml", "host/config/planner_default.yaml");
  put("planner_config", "defaults.json", host::planner::PlannerConfig{}.toJson());
  copySource("rvp_config", "rvp_default.yaml", "host/config/rvp_default.yaml");
  put("rvp_config", "defaults.json", host::planner::RvpConfig{}.toJson());
  for (const std::string name :
       {"world_config", "arm_config", "map_config", "planner_config", "rvp_config"})
    put(name, "empty.yaml", "");
}

void putMapSeeds() {
  // Coarse maps: empty, a few voxels, a ray's free voxels ending in an occupied one.
  auto bt = [&](const std::string& file, const std::function<void(octomap::OcTree&)>& fill) {
    octomap::OcTree tree(0.1);
    fill(tree);
    const fs::path path = scratch() / "seed.bt";
    host::map::writeCoarseBt(tree, path);
    put("coarse_bt", file, slurp(path));
  };
  bt("empty.bt", [](octomap::OcTree&) {});
  bt("voxels.bt", [](octomap::OcTree& t) {
    t.updateNode(octomap::point3d(0.05f, 0.05f, 0.05f), true);
    t.updateNode(octomap::point3d(-0.35f, 0.2f, 1.0f), false);
    t.updateNode(octomap::point3d(0.4f, -0.1f, 0.6f), true);
  });
  bt("ray.bt", [](octomap::OcTree& t) {
    t.insertRay(octomap::point3d(0, 0, 0), octomap::point3d(0.6f, 0.3f, 0.4f));
  });

  // A workspace-tree cache of a coarse grid (0.5 m cells, one direction bin per face).
  {
    robot::ArmConfig arm;
    arm.workspace_samples = 2000;
    arm.workspace_resolution_m = 0.5;
    arm.workspace_direction_bins = 1;
    arm.slider_travel_m = 1.0;
    arm.workspace_cache_dir = "";
    const robot::ArmModel model(arm);
    const fs::path path = scratch() / "workspace.bin";
    robot::WorkspaceTree::build(model).save(path);
    put("workspace_tree", "coarse_0.5m.bin", slurp(path));
  }
}

void putTrialsSeeds() {
  // trials.jsonl: finished trials as the runner appends them, and one cut short.
  {
    const nlohmann::json f0 = {{"gt_center_m", {0, 0, 1}},
                               {"gt_size_mm", 6.0},
                               {"matched", true},
                               {"est_center_m", {0, 0, 1}},
                               {"est_size_mm", 6.5}};
    const nlohmann::json f1 = {
        {"gt_center_m", {0.02, 0, 1}}, {"gt_size_mm", 8.0}, {"matched", false}};
    const nlohmann::json fvp_trial = {
        {"planner", "fvp"},      {"seed", 10},
        {"engine", "grid"},      {"views", 30},
        {"wall_time_s", 100.0},  {"detections", 2},
        {"fruitlets", {f0, f1}}, {"fruitlets_paper_sizing", {f0, f1}}};
    nlohmann::json rvp_trial = fvp_trial;
    rvp_trial["planner"] = "rvp";
    rvp_trial["engine"] = "octomap";
    put("trials", "two_trials.jsonl", fvp_trial.dump() + "\n" + rvp_trial.dump() + "\n");
    put("trials", "cut_short.jsonl", fvp_trial.dump() + "\n\n" + rvp_trial.dump().substr(0, 40));
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FUZZ_DIR (the source tree's fuzz/)\n", argv[0]);
    return 2;
  }
  g_fuzz_dir = argv[1];
  cv::setRNGSeed(1);

  // Simulated worlds' ground truth: the isolated config (no leaves: 4 KB), and the default
  // config without its leaves (they make it 27 KB, and the reader skips them).
  const robot::sim::WorldConfig isolated = robot::sim::WorldConfig::fromYamlFile(
      g_fuzz_dir / ".." / "robot/sim/config/world_isolated.yaml");
  const std::string truth_isolated = robot::sim::World::generate(isolated, 7).groundTruthJson();
  nlohmann::ordered_json truth1 = nlohmann::ordered_json::parse(
      robot::sim::World::generate(robot::sim::WorldConfig{}, 1).groundTruthJson());
  truth1.erase("leaves");

  // Captures: every part (ground truth of a real world), only the required parts, grey left.
  put("capture", "full_16x12", captureInput(16, 12, true, false, truth_isolated));
  put("capture", "instances_16x12", captureInput(16, 12, true, false, truth_isolated, true));
  put("capture", "required_8x6", captureInput(8, 6, false, false, ""));
  put("capture", "grey_left_5x4", captureInput(5, 4, false, true, ""));

  // PLY clouds: the writers' three kinds (a mesh has faces: rejected), and hand-made headers.
  const std::vector<Eigen::Vector3f> pts = {{0, 0, 0}, {1, 2, 3}, {-1.5f, 0.25f, 4}};
  put("ply", "points_3", plyFile([&](const fs::path& p) { host::writePlyPoints(p, pts); }));
  put("ply", "points_0", plyFile([&](const fs::path& p) { host::writePlyPoints(p, {}); }));
  put("ply", "coloured_3", plyFile([&](const fs::path& p) {
        host::writePlyColoredPoints(p, pts, {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}}, "seed");
      }));
  put("ply", "mesh_1", plyFile([&](const fs::path& p) {
        host::writePlyMesh(p, pts, {{0, 1, 2}}, "seed");
      }));
  {
    std::string ply =
        "ply\r\nformat binary_little_endian 1.0\r\nobj_info other tool\r\nelement vertex 2\r\n"
        "property double t\r\nproperty float z\r\nproperty uchar flag\r\nproperty float x\r\n"
        "property ushort id\r\nproperty float y\r\nend_header\r\n";
    ply.append(2 * (8 + 4 + 1 + 4 + 2 + 4), '\x01');
    put("ply", "extra_properties_crlf", ply);
  }

  putConfigSeeds();

  put("ground_truth", "isolated_seed7.json", truth_isolated);
  put("ground_truth", "default_seed1_no_leaves.json", truth1.dump(1));
  put("ground_truth", "minimal.json",
      R"({"fruitlets": [{"center_m": [0, 0.1, 1], "gt_size_mm": 6.5}]})");

  putMapSeeds();

  putTrialsSeeds();
  return 0;
}
