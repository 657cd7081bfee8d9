// The `fvp` program on broken captures, configs and option values, run as a user runs it:
// each case must end with exit code 1 (a bad file or value) or 2 (a usage error), never a
// signal, with a message naming the file and field or the option, and leave no half-written
// (*.tmp-*) or result file behind. A second group checks the documented warnings.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>
#include <vector>

#include "fvp/host/core/subprocess.h"
#include "fvp/host/planner/view_overhead.h"
#include "fvp/trials/experiment_directory.h"

namespace fs = std::filesystem;

namespace {

const char* const kFvp = FVP_BINARY;

void writeText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

/// camera.yaml of a 320x240 camera looking along +z from the origin, with `extra` lines
/// replacing the defaults of the same key.
std::string cameraYaml(const std::vector<std::pair<std::string, std::string>>& overrides = {}) {
  std::vector<std::pair<std::string, std::string>> fields = {
      {"format_version", "1"}, {"width", "320"}, {"height", "240"}, {"fx", "300"},
      {"fy", "300"},           {"cx", "159.5"},  {"cy", "119.5"},   {"baseline_m", "0.05"}};
  for (auto& [key, value] : fields)
    for (const auto& [k, v] : overrides)
      if (k == key) value = v;
  std::string text;
  for (const auto& [key, value] : fields) text += key + ": " + value + "\n";
  text += "T_world_camera: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n";
  return text;
}

/// A capture of uniform grey images (no fruitlet, no tag) at dir.
void writeGreyCapture(const fs::path& dir, int width = 320, int height = 240,
                      const std::string& yaml = cameraYaml()) {
  fs::create_directories(dir);
  const cv::Mat grey(height, width, CV_8UC3, cv::Scalar(128, 128, 128));
  cv::imwrite((dir / "left.png").string(), grey);
  cv::imwrite((dir / "right.png").string(), grey);
  writeText(dir / "camera.yaml", yaml);
}

/// An experiment directory of one fvp trial (seed 1, --clock fixed --max-views 1 --backend
/// cpu --budget-s 180 --stop budget) whose manifest's error_scale and trial's engine are
/// given: what `fvp experiment` writes, edited.
void writeExperiment(const fs::path& dir, const std::string& error_scale,
                     const std::string& engine) {
  nlohmann::ordered_json m = {{"format", "fvp-experiment-manifest"},
                              {"version", 1},
                              {"kind", "run"},
                              {"budget_s", 180.0},
                              {"clock", "fixed"},
                              {"stop", "budget"},
                              {"max_views", 1},
                              {"register_views", false},
                              {"confirm_detections", false},
                              {"release_left_out", false},
                              {"view_overhead_s", fvp::host::planner::kDefaultViewOverheadS},
                              {"guided_stereo", fvp::trials::TrialOptions{}.guided_stereo},
                              {"error_scale", error_scale},
                              {"clock_charges", fvp::trials::ExperimentManifest::clockChargesFor(
                                                    fvp::trials::TrialOptions{}.guided_stereo)},
                              {"world_config", {{"path", ""}, {"fnv1a64", ""}}},
                              {"planner_config", {{"path", ""}, {"fnv1a64", ""}}},
                              {"arm_config", {{"path", ""}, {"fnv1a64", ""}}},
                              {"engine", ""},
                              {"backend", "cpu"},
                              {"planners", {"fvp"}},
                              {"trials", 1},
                              {"first_seed", 1},
                              {"shard", {{"index", 0}, {"count", 1}}}};
  writeText(dir / "manifest.json", m.dump(2) + "\n");
  const nlohmann::json trial = {
      {"planner", "fvp"},
      {"seed", 1},
      {"engine", engine},
      {"fruitlets", nlohmann::json::array({{{"gt_size_mm", 10.0}, {"matched", false}}})}};
  writeText(dir / "trials.jsonl", trial.dump() + "\n");
}

/// Issue 38's gnuplot injection, touching dir/PWNED if it ever ran.
std::string injection(const fs::path& dir, const std::string& before) {
  return before + "'\nsystem \"touch " + (dir / "PWNED").string() + "\"\n#";
}

struct BadInput {
  std::string name;
  /// Makes the case's files under dir and returns the command line (without the program).
  std::function<std::vector<std::string>(const fs::path& dir)> setup;
  int exit_code;                      ///< 1: bad file or value; 2: usage error
  std::vector<std::string> messages;  ///< each must appear in stderr
  std::vector<std::string> absent;    ///< paths under dir that must not exist afterwards
};

std::ostream& operator<<(std::ostream& os, const BadInput& c) {
  return os << c.name;
}

std::vector<std::string> temporaries(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos)
      found.push_back(e.path().string());
  return found;
}

std::string p(const fs::path& path) {
  return path.string();
}

const std::vector<BadInput>& cases() {
  static const std::vector<BadInput> table = {
      {"SizeFocalLengthInMetres",
       [](const fs::path& d) {
         writeGreyCapture(d / "cap", 320, 240, cameraYaml({{"fx", "0.004"}, {"fy", "0.004"}}));
         return std::vector<std::string>{"size", "--captures", p(d / "cap"), "--backend",
                                         "cpu",  "--out",      p(d / "out")};
       },
       1,
       {"camera.yaml: field 'fx': expected a focal length in pixels"},
       {"out/fruitlets.json"}},
      {"SizeTwoPixelImages",
       [](const fs::path& d) {
         writeGreyCapture(d / "cap", 2, 2, cameraYaml({{"width", "2"}, {"height", "2"}}));
         return std::vector<std::string>{"size", "--captures", p(d / "cap"), "--out", p(d / "out")};
       },
       1,
       {"camera.yaml: field 'width': expected an image side of 32 to 16384 pixels, got 2"},
       {"out/fruitlets.json"}},
      {"SizeNonFiniteIntrinsic",
       [](const fs::path& d) {
         writeGreyCapture(d / "cap", 320, 240, cameraYaml({{"cx", ".nan"}}));
         return std::vector<std::string>{"size", "--captures", p(d / "cap"), "--out", p(d / "out")};
       },
       1,
       {"camera.yaml: field 'cx'"},
       {"out/fruitlets.json"}},
      {"SizeViewWithoutCameraYaml",
       [](const fs::path& d) {
         writeGreyCapture(d / "set" / "000");
         writeGreyCapture(d / "set" / "001");
         fs::remove(d / "set" / "001" / "camera.yaml");
         return std::vector<std::string>{"size", "--captures", p(d / "set"), "--out", p(d / "out")};
       },
       1,
       {"001: holds capture files but no camera.yaml"},
       {"out/fruitlets.json"}},
      {"SizeStrayCameraYamlAtTheSetsRoot",
       [](const fs::path& d) {
         writeGreyCapture(d / "set" / "000");
         writeText(d / "set" / "camera.yaml", cameraYaml());
         return std::vector<std::string>{"size", "--captures", p(d / "set"), "--out", p(d / "out")};
       },
       1,
       {"holds camera.yaml and capture subdirectories too"},
       {"out/fruitlets.json"}},
      {"SizeOutIsAFile",
       [](const fs::path& d) {
         writeGreyCapture(d / "cap");
         writeText(d / "out", "not a directory");
         return std::vector<std::string>{"size", "--captures", p(d / "cap"), "--out", p(d / "out")};
       },
       1,
       {"out': exists and is not a directory"},
       {}},
      {"RunOutIsAFile",
       [](const fs::path& d) {
         writeText(d / "out", "x");
         return std::vector<std::string>{"run", "--seed", "1",         "--backend",
                                         "cpu", "--out",  p(d / "out")};
       },
       1,
       {"exists and is not a directory"},
       {}},
      {"MapOutIsAFile",
       [](const fs::path& d) {
         writeText(d / "out", "x");
         return std::vector<std::string>{"map", "--seed", "1", "--out", p(d / "out")};
       },
       1,
       {"--out '", "exists and is not a directory"},
       {}},
      {"PlanOutIsAFile",
       [](const fs::path& d) {
         writeText(d / "out", "x");
         return std::vector<std::string>{"plan", "--seed", "1",         "--backend",
                                         "cpu",  "--out",  p(d / "out")};
       },
       1,
       {"exists and is not a directory"},
       {}},
      {"CaptureOutIsAFile",
       [](const fs::path& d) {
         writeText(d / "out", "x");
         return std::vector<std::string>{"capture", "--seed", "1", "--out", p(d / "out")};
       },
       1,
       {"exists and is not a directory"},
       {}},
      {"CapturePoseNaN",
       [](const fs::path& d) {
         return std::vector<std::string>{"capture",         "--seed", "1",         "--pose",
                                         "nan,0,1,0,0,0,1", "--out",  p(d / "out")};
       },
       1,
       {"--pose: 'nan' is not a finite number"},
       {"out/camera.yaml"}},
      {"CapturePoseFarAway",
       [](const fs::path& d) {
         return std::vector<std::string>{"capture",         "--seed", "1",         "--pose",
                                         "1e9,0,1,0,0,0,1", "--out",  p(d / "out")};
       },
       1,
       {"--pose: field 'x,y,z': expected a position within 1000 m"},
       {"out/camera.yaml"}},
      {"CaptureSetOverAnOlderSet",
       [](const fs::path& d) {
         writeGreyCapture(d / "out" / "000");
         return std::vector<std::string>{"capture", "--seed", "1",         "--views",
                                         "2",       "--out",  p(d / "out")};
       },
       1,
       {"already holds captures (000)"},
       {"out/001"}},
      {"SeedNegative",
       [](const fs::path& d) {
         return std::vector<std::string>{"run", "--seed", "-1", "--out", p(d / "out")};
       },
       2,
       {"--seed", "non-negative decimal integer, got '-1'"},
       {"out"}},
      {"SeedOctal",
       [](const fs::path& d) {
         return std::vector<std::string>{"plan", "--seed", "010", "--out", p(d / "out")};
       },
       2,
       {"--seed", "without leading zeros"},
       {"out"}},
      {"BudgetInfinite",
       [](const fs::path& d) {
         return std::vector<std::string>{"run", "--budget-s", "inf", "--out", p(d / "out")};
       },
       2,
       {"--budget-s", "finite"},
       {"out"}},
      {"MaxViewsNegative",
       [](const fs::path& d) {
         return std::vector<std::string>{"run", "--max-views", "-1", "--out", p(d / "out")};
       },
       2,
       {"--max-views"},
       {"out"}},
      {"UnknownSubcommand",
       [](const fs::path&) {
         return std::vector<std::string>{"frobnicate", "--out", "x"};
       },
       2,
       {"unknown subcommand 'frobnicate'"},
       {}},
      {"RvpConfigNaN",
       [](const fs::path& d) {
         writeText(d / "rvp.yaml", "roi_utility_threshold: .nan\n");
         return std::vector<std::string>{"plan",  "--planner", "rvp", "--config", p(d / "rvp.yaml"),
                                         "--out", p(d / "out")};
       },
       1,
       {"rvp.yaml': key 'roi_utility_threshold': expected a number (finite), got '.nan'"},
       {"out/plan.json"}},
      {"PlannerConfigInfinity",
       [](const fs::path& d) {
         writeText(d / "fvp.yaml", "alpha_per_m: .inf\n");
         return std::vector<std::string>{"run", "--config", p(d / "fvp.yaml"), "--backend",
                                         "cpu", "--out",    p(d / "out")};
       },
       1,
       {"fvp.yaml': key 'alpha_per_m': expected a number (finite)"},
       {"out/result.json"}},
      {"WorldConfigListAsKey",
       [](const fs::path& d) {
         writeText(d / "world.yaml", "[a, b]: 1\n");
         return std::vector<std::string>{"run", "--world", p(d / "world.yaml"), "--backend",
                                         "cpu", "--out",   p(d / "out")};
       },
       1,
       {"world.yaml': expected keys that are names, got a list as a key"},
       {"out/result.json"}},
      {"WorldConfigListAsNumber",
       [](const fs::path& d) {
         writeText(d / "world.yaml", "cluster_spread_m: [1, 2]\n");
         return std::vector<std::string>{"capture", "--world", p(d / "world.yaml"), "--seed",
                                         "1",       "--out",   p(d / "out")};
       },
       1,
       {"world.yaml': key 'cluster_spread_m': expected a number"},
       {"out/camera.yaml"}},
      {"WorldConfigSyntaxError",
       [](const fs::path& d) {
         writeText(d / "world.yaml", "cluster_spread_m: [1, 2\n");
         return std::vector<std::string>{"map", "--world", p(d / "world.yaml"), "--out",
                                         p(d / "out")};
       },
       1,
       {"world.yaml': cannot read YAML"},
       {"out/coarse.bt"}},
      {"MapConfigIsADirectory",
       [](const fs::path& d) {
         fs::create_directories(d / "map.yaml");
         return std::vector<std::string>{"map", "--map-config", p(d / "map.yaml"), "--out",
                                         p(d / "out")};
       },
       2,
       {"--map-config", "map.yaml"},
       {"out/coarse.bt"}},
      {"MapConfigNumberAsText",
       [](const fs::path& d) {
         writeText(d / "map.yaml", "fine_voxel_size_m: fine\n");
         return std::vector<std::string>{"map", "--map-config", p(d / "map.yaml"), "--out",
                                         p(d / "out")};
       },
       1,
       {"map.yaml': key 'fine_voxel_size_m': expected a number, got 'fine'"},
       {"out/coarse.bt"}},
      {"BudgetZero",
       [](const fs::path& d) {
         return std::vector<std::string>{"run", "--budget-s", "0", "--out", p(d / "out")};
       },
       2,
       {"--budget-s", "expected a number above 0, got '0'"},
       {"out"}},
      {"ExperimentPlannerTwice",
       [](const fs::path& d) {
         return std::vector<std::string>{"experiment", "--planners", "fvp,fvp",   "--trials",
                                         "1",          "--out",      p(d / "exp")};
       },
       1,
       {"--planners lists 'fvp' twice"},
       {"exp/trials.jsonl"}},
      {"ExperimentShardOfThreeParts",
       [](const fs::path& d) {
         return std::vector<std::string>{"experiment", "--shard", "1/2/3", "--out", p(d / "exp")};
       },
       2,
       {"--shard: expected i/n", "'1/2/3'"},
       {"exp/trials.jsonl"}},
      {"MergeADirectoryWithoutManifest",
       [](const fs::path& d) {
         writeText(d / "old" / "trials.jsonl", "");
         return std::vector<std::string>{"merge", "--out", p(d / "merged"), p(d / "old")};
       },
       1,
       {"old has trials.jsonl but no manifest.json"},
       {"merged/trials.jsonl", "merged/table1.md"}},
      {"MergeOutHoldsShellQuotes",
       [](const fs::path& d) {
         writeText(d / "old" / "trials.jsonl", "");
         return std::vector<std::string>{"merge", "--out", p(d / "x'; touch PWNED; echo '"),
                                         p(d / "old")};
       },
       1,
       {"no manifest.json"},
       {"PWNED"}},
      // --out "" wrote nowhere and exited 0: every --out is a usage error when empty.
      {"RunOutEmpty",
       [](const fs::path&) {
         return std::vector<std::string>{"run", "--seed", "1", "--out", ""};
       },
       2,
       {"--out: expected a directory, got an empty path"},
       {}},
      {"SizeOutEmpty",
       [](const fs::path& d) {
         writeGreyCapture(d / "cap");
         return std::vector<std::string>{"size", "--captures", p(d / "cap"), "--out", ""};
       },
       2,
       {"--out: expected a directory, got an empty path"},
       {}},
      {"PlanOutEmpty",
       [](const fs::path&) {
         return std::vector<std::string>{"plan", "--seed", "1", "--out", ""};
       },
       2,
       {"--out: expected a directory, got an empty path"},
       {}},
      // Output paths checked before the work: a `views` that is a file fails before the trial.
      {"RunViewsIsAFile",
       [](const fs::path& d) {
         writeText(d / "out" / "views", "a file where the trial writes its views");
         return std::vector<std::string>{"run",       "--seed", "3",     "--max-views", "1",
                                         "--backend", "cpu",    "--out", p(d / "out")};
       },
       1,
       {"views exists and is not a directory"},
       {"out/result.json"}},
      {"RunResultIsADirectory",
       [](const fs::path& d) {
         fs::create_directories(d / "out" / "result.json");
         return std::vector<std::string>{"run", "--seed", "3",         "--backend",
                                         "cpu", "--out",  p(d / "out")};
       },
       1,
       {"result.json is a directory"},
       {"out/report.md"}},
      // The capture reader opens regular files of a bounded size only: a FIFO hung it, and
      // /dev/zero or a sparse 30 GB file were read until memory ran out. A stale temporary of
      // a dead process in --out is removed (the table checks that none is left).
      {"SizeMaskIsAFifo",
       [](const fs::path& d) {
         writeGreyCapture(d / "cap");
         ::mkfifo((d / "cap" / "mask.png").c_str(), 0600);
         writeText(d / "out" / "fruitlets.json.tmp-2147483-0", "left by a killed run");
         return std::vector<std::string>{"size", "--captures", p(d / "cap"), "--out", p(d / "out")};
       },
       1,
       {"mask.png: expected a regular file (the PNG image), got a FIFO"},
       {"out/fruitlets.json"}},
      {"SizeCameraYamlIsAFifo",
       [](const fs::path& d) {
         writeGreyCapture(d / "cap");
         fs::remove(d / "cap" / "camera.yaml");
         ::mkfifo((d / "cap" / "camera.yaml").c_str(), 0600);
         return std::vector<std::string>{"size", "--captures", p(d / "cap"), "--out", p(d / "out")};
       },
       1,
       {"camera.yaml: expected a regular file (the camera model), got a FIFO"},
       {"out/fruitlets.json"}},
      {"SizeLeftImageIsDevZero",
       [](const fs::path& d) {
         writeGreyCapture(d / "cap");
         fs::remove(d / "cap" / "left.png");
         fs::create_symlink("/dev/zero", d / "cap" / "left.png");
         return std::vector<std::string>{"size", "--captures", p(d / "cap"), "--out", p(d / "out")};
       },
       1,
       {"left.png: expected a regular file (the PNG image), got a character device"},
       {"out/fruitlets.json"}},
      {"SizeLeftImageIsHugeAndSparse",
       [](const fs::path& d) {
         writeGreyCapture(d / "cap");
         fs::resize_file(d / "cap" / "left.png", std::uintmax_t{30} << 30);
         return std::vector<std::string>{"size", "--captures", p(d / "cap"), "--out", p(d / "out")};
       },
       1,
       {"left.png: 32212254720 bytes, more than the 17391616 bytes a PNG image may have"},
       {"out/fruitlets.json"}},
      // Memory bounds: what a setting may ask for follows from what it means.
      {"WorldConfigOfTwoMegabytes",
       [](const fs::path& d) {
         std::string list = "fruitlet_count: [";
         while (list.size() < (std::size_t{2} << 20)) list += "1, ";
         writeText(d / "world.yaml", list + "1]\n");
         return std::vector<std::string>{"run",   "--seed",    "1", "--world", p(d / "world.yaml"),
                                         "--out", p(d / "out")};
       },
       1,
       {"world.yaml", "bytes a config file may have"},
       {"out/result.json"}},
      {"ArmWorkspaceTreeOfTerabytes",
       [](const fs::path& d) {
         writeText(d / "arm.yaml", "workspace_resolution_m: 0.005\nworkspace_direction_bins: 16\n");
         return std::vector<std::string>{"run",   "--seed",          "1",
                                         "--arm", p(d / "arm.yaml"), "--backend",
                                         "cpu",   "--out",           p(d / "out")};
       },
       1,
       {"arm.yaml", "'workspace_resolution_m' = 0.005", "workspace tree of", "at most 4 GiB"},
       {"out/result.json"}},
      {"PlannerTenMillionSamples",
       [](const fs::path& d) {
         writeText(d / "planner.yaml", "roi_samples: 10000000\n");
         return std::vector<std::string>{
             "run",       "--seed", "1",     "--config",  p(d / "planner.yaml"),
             "--backend", "cpu",    "--out", p(d / "out")};
       },
       1,
       {"roi_samples", "0 to 100000 candidates"},
       {"out/result.json"}},
      {"ExperimentTwoBillionTrials",
       [](const fs::path& d) {
         return std::vector<std::string>{"experiment", "--planners", "fvp",       "--trials",
                                         "2147483647", "--out",      p(d / "exp")};
       },
       1,
       {"--trials 2147483647: expected at most 100000"},
       {"exp/manifest.json", "exp/trials.jsonl"}},
      // merge --out: new, empty or an earlier merge, nothing else.
      {"MergeIntoADirectoryWithAUsersFile",
       [](const fs::path& d) {
         // An empty shard: a valid experiment made without running a trial.
         const auto made =
             fvp::host::runProgram({kFvp, "experiment", "--planners", "fvp", "--trials", "2",
                                    "--shard", "3/4", "--out", p(d / "shard")},
                                   "");
         EXPECT_EQ(made.exit_code, 0) << made.stderr_text;
         writeText(d / "merged" / "table1.md", "the user's own table");
         return std::vector<std::string>{"merge", "--out", p(d / "merged"), p(d / "shard")};
       },
       1,
       {"is not empty (it holds table1.md) and is not an earlier merge"},
       {"merged/manifest.json", "merged/trials.jsonl"}},
      // A single view into a capture set left a stray camera.yaml that broke the set.
      {"CaptureOneViewIntoASet",
       [](const fs::path& d) {
         writeGreyCapture(d / "set" / "000");
         return std::vector<std::string>{"capture", "--seed", "1", "--out", p(d / "set")};
       },
       1,
       {"holds a capture set (000/camera.yaml)"},
       {"set/camera.yaml", "set/left.png"}},

      // Issue 38, 1: text from experiment files never reaches a gnuplot script.
      {"SensitivityErrorGroupInjection",
       [](const fs::path& d) {
         writeExperiment(d / "exp", injection(d, "wind") + "=1", "");
         return std::vector<std::string>{"sensitivity", "--out", p(d / "sens"), p(d / "exp")};
       },
       1,
       {"manifest.json: field 'error_scale': expected \"\" or GROUP=FACTOR"},
       {"PWNED", "sens/sensitivity.png", "sens/sensitivity.json"}},
      {"MergeTrialEngineInjection",
       [](const fs::path& d) {
         writeExperiment(d / "exp", "", injection(d, "grid"));
         return std::vector<std::string>{"merge", "--out", p(d / "merged"), p(d / "exp")};
       },
       1,
       {"trials.jsonl: line 1: field 'engine': expected \"\" (the planner's own) or a map engine "
        "name"},
       {"PWNED", "merged/trials.jsonl", "merged/accuracy_vs_time.png"}},
      {"ResumeTrialEngineInjection",
       [](const fs::path& d) {
         writeExperiment(d / "exp", "", injection(d, "octomap"));
         return std::vector<std::string>{
             "experiment", "--planners", "fvp",   "--trials",    "1",     "--first-seed",
             "1",          "--clock",    "fixed", "--max-views", "1",     "--backend",
             "cpu",        "--budget-s", "180",   "--resume",    "--out", p(d / "exp")};
       },
       1,
       {"trials.jsonl: line 1: field 'engine'"},
       {"PWNED", "exp/summary.json"}},
      // 5: a factor the world config cannot take is refused, not clamped.
      {"ErrorScaleBeyondTheWorldConfig",
       [](const fs::path& d) {
         writeText(d / "world.yaml", "hand_eye_translation_sigma_m: 0.0015\n");
         return std::vector<std::string>{
             "experiment",        "--planners",    "fvp",     "--trials", "1",         "--world",
             p(d / "world.yaml"), "--error-scale", "pose=20", "--out",    p(d / "exp")};
       },
       1,
       {"--error-scale: error scale pose=20: hand_eye_translation_sigma_m would be 0.03",
        "the largest factor this world config allows for pose is 13.3333", "world.yaml"},
       {"exp/manifest.json", "exp/world.yaml"}},
      {"ErrorScaleHuge",
       [](const fs::path& d) {
         return std::vector<std::string>{"experiment", "--error-scale", "pose=1e308", "--out",
                                         p(d / "exp")};
       },
       2,
       {"--error-scale", "FACTOR a decimal number from 0 to 1000"},
       {"exp"}},
      // 6: one rule for numbers and keys in every YAML file.
      {"WorldConfigOctalInteger",
       [](const fs::path& d) {
         writeText(d / "world.yaml", "max_fruitlets: 012\n");
         return std::vector<std::string>{"capture", "--world", p(d / "world.yaml"), "--seed",
                                         "1",       "--out",   p(d / "out")};
       },
       1,
       {"world.yaml': key 'max_fruitlets': expected an integer (decimal", "got '012'"},
       {"out/camera.yaml"}},
      {"WorldConfigHexInteger",
       [](const fs::path& d) {
         writeText(d / "world.yaml", "max_fruitlets: 0x05\n");
         return std::vector<std::string>{"capture", "--world", p(d / "world.yaml"), "--seed",
                                         "1",       "--out",   p(d / "out")};
       },
       1,
       {"key 'max_fruitlets': expected an integer", "got '0x05'"},
       {"out/camera.yaml"}},
      {"WorldConfigDuplicateKey",
       [](const fs::path& d) {
         writeText(d / "world.yaml", "max_fruitlets: 5\nmin_fruitlets: 2\nmax_fruitlets: 6\n");
         return std::vector<std::string>{"capture", "--world", p(d / "world.yaml"), "--seed",
                                         "1",       "--out",   p(d / "out")};
       },
       1,
       {"world.yaml': key 'max_fruitlets' appears twice (lines 1 and 3)"},
       {"out/camera.yaml"}},
      {"WorldConfigTwoDocuments",
       [](const fs::path& d) {
         writeText(d / "world.yaml", "max_fruitlets: 5\n---\nmax_fruitlets: 6\n");
         return std::vector<std::string>{"capture", "--world", p(d / "world.yaml"), "--seed",
                                         "1",       "--out",   p(d / "out")};
       },
       1,
       {"world.yaml': expected one YAML document, got 2 or more"},
       {"out/camera.yaml"}},
      {"WorldConfigNestedTooDeeply",
       [](const fs::path& d) {
         std::string nested = "max_fruitlets: ";
         nested.append(5000, '[').append("\n");
         writeText(d / "world.yaml", nested);
         return std::vector<std::string>{"capture", "--world", p(d / "world.yaml"), "--seed",
                                         "1",       "--out",   p(d / "out")};
       },
       1,
       {"world.yaml': cannot read YAML: lists or mappings nested too deeply"},
       {"out/camera.yaml"}},
      {"CameraYamlDuplicateKey",
       [](const fs::path& d) {
         writeGreyCapture(d / "set" / "000", 320, 240, cameraYaml() + "fx: 3000\n");
         return std::vector<std::string>{"size", "--captures", p(d / "set"), "--backend",
                                         "cpu",  "--out",      p(d / "out")};
       },
       1,
       {"camera.yaml: key 'fx' appears twice"},
       {"out/fruitlets.json"}},
      {"CameraYamlOctalWidth",
       [](const fs::path& d) {
         writeGreyCapture(d / "set" / "000", 320, 240, cameraYaml({{"width", "0320"}}));
         return std::vector<std::string>{"size", "--captures", p(d / "set"), "--backend",
                                         "cpu",  "--out",      p(d / "out")};
       },
       1,
       {"camera.yaml: field 'width'", "got '0320'"},
       {"out/fruitlets.json"}},
      // 7: a quaternion whose norm overflows or is far from 1.
      {"CapturePoseQuaternionOverflow",
       [](const fs::path& d) {
         return std::vector<std::string>{"capture",           "--seed", "1",         "--pose",
                                         "0,0,0,1e308,0,0,1", "--out",  p(d / "out")};
       },
       1,
       {"--pose: field 'qx,qy,qz,qw': expected a unit quaternion (norm within 0.01 of 1), got "
        "a component of 1e+308"},
       {"out/camera.yaml"}},
      {"CapturePoseQuaternionNotUnit",
       [](const fs::path& d) {
         return std::vector<std::string>{"capture",         "--seed", "1",         "--pose",
                                         "0,0,1,0,0,0,0.5", "--out",  p(d / "out")};
       },
       1,
       {"expected a unit quaternion (norm within 0.01 of 1), got norm 0.5"},
       {"out/camera.yaml"}},
      // 13: clear messages.
      {"SizeLeftPngIsADirectory",
       [](const fs::path& d) {
         writeGreyCapture(d / "set" / "000");
         fs::remove(d / "set" / "000" / "left.png");
         fs::create_directories(d / "set" / "000" / "left.png");
         return std::vector<std::string>{"size", "--captures", p(d / "set"), "--backend",
                                         "cpu",  "--out",      p(d / "out")};
       },
       1,
       {"left.png: expected a regular file (the PNG image), got a directory"},
       {"out/fruitlets.json"}},
      {"PerceptionRegionRadiusHuge",
       [](const fs::path& d) {
         writeGreyCapture(d / "set" / "000");
         writeText(d / "perception.yaml", "region_radius_m: 1e9\n");
         return std::vector<std::string>{
             "size",      "--captures", p(d / "set"), "--config",  p(d / "perception.yaml"),
             "--backend", "cpu",        "--out",      p(d / "out")};
       },
       1,
       {"perception.yaml': key 'region_radius_m': expected a radius above 0 and at most 0.5 m"},
       {"out/fruitlets.json"}},
      {"OutIsADanglingSymlink",
       [](const fs::path& d) {
         fs::create_directory_symlink(d / "gone", d / "out");
         return std::vector<std::string>{"capture", "--seed", "1", "--out", p(d / "out")};
       },
       1,
       {"a symbolic link to '", "gone', which does not exist"},
       {"gone"}},
      {"ShardNotANumber",
       [](const fs::path& d) {
         return std::vector<std::string>{"experiment", "--shard", "0/4x", "--out", p(d / "exp")};
       },
       2,
       {"--shard: expected i/n", "'4x' is not a decimal integer"},
       {"exp"}},
      {"BudgetLeadingSpace",
       [](const fs::path& d) {
         return std::vector<std::string>{"run", "--budget-s", " 5", "--out", p(d / "out")};
       },
       2,
       {"--budget-s", "expected a finite decimal number, got ' 5'"},
       {"out"}},
      {"BudgetTrailingSpace",
       [](const fs::path& d) {
         return std::vector<std::string>{"run", "--budget-s", "5 ", "--out", p(d / "out")};
       },
       2,
       {"--budget-s", "expected a finite decimal number, got '5 '"},
       {"out"}},
  };
  return table;
}

class BadInputs : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadInputs, ExitWithAClearErrorAndWriteNothing) {
  const BadInput& c = GetParam();
  const fs::path dir = fs::path(::testing::TempDir()) / ("fvp_bad_inputs_" + c.name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::vector<std::string> argv = {kFvp};
  for (const std::string& a : c.setup(dir)) argv.push_back(a);
  const fvp::host::SubprocessResult run = fvp::host::runProgram(argv, "");
  SCOPED_TRACE("stderr: " + run.stderr_text + "\nstdout: " + run.stdout_text);
  EXPECT_EQ(run.exit_code, c.exit_code) << "-1 means a signal ended fvp";
  for (const std::string& m : c.messages)
    EXPECT_NE(run.stderr_text.find(m), std::string::npos) << "missing: " << m;
  for (const std::string& a : c.absent) EXPECT_FALSE(fs::exists(dir / a)) << a;
  EXPECT_EQ(temporaries(dir), std::vector<std::string>{});
  // Bounds are printed as people write them (CLI::PositiveNumber printed 309 digits).
  EXPECT_EQ(run.stderr_text.find("0000000000000000000000"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Fvp, BadInputs, ::testing::ValuesIn(cases()),
                         [](const auto& info) { return info.param.name; });

// A set whose images hold nothing HSV segmentation or the tag detector can find is not an
// error: it is sized (to nothing) with printed warnings that fruitlets.json records too.
TEST(Warnings, GreyCapturesAreSizedWithPrintedAndRecordedWarnings) {
  const fs::path dir = fs::path(::testing::TempDir()) / "fvp_bad_inputs_grey";
  fs::remove_all(dir);
  writeGreyCapture(dir / "set" / "000");
  writeGreyCapture(dir / "set" / "001");
  fs::create_directories(dir / "set" / "notes");  // not a capture: skipped with a warning
  const auto run = fvp::host::runProgram(
      {kFvp, "size", "--captures", p(dir / "set"), "--backend", "cpu", "--out", p(dir / "out")},
      "");
  SCOPED_TRACE(run.stderr_text);
  ASSERT_EQ(run.exit_code, 0);
  EXPECT_NE(run.stderr_text.find("fvp: warning: "), std::string::npos);
  EXPECT_NE(run.stderr_text.find("000: no fruitlet pixels segmented"), std::string::npos);
  EXPECT_NE(run.stderr_text.find("notes: not a capture (no camera.yaml), skipped"),
            std::string::npos);
  EXPECT_NE(run.stderr_text.find("no capture showed the AprilTag"), std::string::npos);
  std::ifstream in(dir / "out" / "fruitlets.json");
  const nlohmann::json result = nlohmann::json::parse(in);
  EXPECT_EQ(result["warnings"].size(), 4u);  // two captures, the skipped folder, no tag
  EXPECT_EQ(result["captures"][0]["fruitlet_pixels"], 0);
}

// A figure is an optional extra: without gnuplot the trial still writes result.json and
// report.md, warns, and records why path.png is missing. The run also removes what an
// earlier run left in the same --out (a stale view and figure).
TEST(Warnings, ATrialWithoutGnuplotKeepsItsResultAndClearsAnEarlierRun) {
  const fs::path dir = fs::path(::testing::TempDir()) / "fvp_bad_inputs_no_gnuplot";
  fs::remove_all(dir);
  writeText(dir / "out" / "views" / "099.png", "stale");
  writeText(dir / "out" / "path.png", "stale");
  writeText(dir / "out" / "notes.txt", "the user's own file");
  const char* old_path = std::getenv("PATH");
  const std::string saved = old_path ? old_path : "";
  ::setenv("PATH", "/nonexistent", 1);
  const auto run = fvp::host::runProgram({kFvp, "run", "--seed", "3", "--max-views", "1", "--clock",
                                          "fixed", "--backend", "cpu", "--out", p(dir / "out")},
                                         "");
  ::setenv("PATH", saved.c_str(), 1);
  SCOPED_TRACE(run.stderr_text);
  ASSERT_EQ(run.exit_code, 0);
  EXPECT_NE(run.stderr_text.find("fvp: warning: path.png not drawn"), std::string::npos);
  std::ifstream in(dir / "out" / "result.json");
  const nlohmann::json result = nlohmann::json::parse(in);
  ASSERT_EQ(result["warnings"].size(), 1u);
  EXPECT_NE(result["warnings"][0].get<std::string>().find("cannot start 'gnuplot'"),
            std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "out" / "report.md"));
  EXPECT_TRUE(fs::exists(dir / "out" / "views" / "000.png"));
  EXPECT_FALSE(fs::exists(dir / "out" / "views" / "099.png"));
  EXPECT_FALSE(fs::exists(dir / "out" / "path.png"));
  EXPECT_TRUE(fs::exists(dir / "out" / "notes.txt"));
}

/// Runs fvp with a resource limit set for it (and restored here after): the limit is
/// inherited by the child. SIGXFSZ is ignored as fvp ignores it, so an over-size write fails
/// with EFBIG ("File too large"), the way a full disk fails it with ENOSPC.
fvp::host::SubprocessResult runLimited(const std::vector<std::string>& argv, int resource,
                                       rlim_t limit) {
  struct rlimit saved {};
  ::getrlimit(resource, &saved);
  struct rlimit lowered = saved;
  lowered.rlim_cur = limit;
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  ::setrlimit(resource, &lowered);
  fvp::host::SubprocessResult run = fvp::host::runProgram(argv, "");
  ::setrlimit(resource, &saved);
  std::signal(SIGXFSZ, old_handler);
  return run;
}

std::vector<std::string> lines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// One writer per output directory: while another process holds the lock, every writer
// fails at once, naming the directory and the holder, and writes nothing.
TEST(Outputs, ASecondWriterIsRefusedNamingTheFirst) {
  const fs::path dir = fs::path(::testing::TempDir()) / "fvp_bad_inputs_locked";
  fs::remove_all(dir);
  writeGreyCapture(dir / "cap");
  const auto shard = fvp::host::runProgram({kFvp, "experiment", "--planners", "fvp", "--trials",
                                            "2", "--shard", "3/4", "--out", p(dir / "shard")},
                                           "");
  ASSERT_EQ(shard.exit_code, 0) << shard.stderr_text;
  fs::create_directories(dir / "out");
  const int fd = ::open((dir / "out" / ".fvp.lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  const std::string holder = "pid 4242: fvp experiment --out out";
  ASSERT_EQ(::write(fd, holder.data(), holder.size()), ssize_t(holder.size()));
  const std::string out = p(dir / "out");
  const std::vector<std::vector<std::string>> writers = {
      {"experiment", "--planners", "fvp", "--trials", "1", "--out", out},
      {"experiment", "--planners", "fvp", "--trials", "1", "--error-scale", "wind=2", "--out", out},
      {"run", "--seed", "1", "--backend", "cpu", "--out", out},
      {"size", "--captures", p(dir / "cap"), "--backend", "cpu", "--out", out},
      {"capture", "--seed", "1", "--out", out},
      {"map", "--seed", "1", "--views", "1", "--out", out},
      {"plan", "--seed", "1", "--backend", "cpu", "--out", out},
      {"merge", "--out", out, p(dir / "shard")}};
  for (const auto& args : writers) {
    std::vector<std::string> argv = {kFvp};
    argv.insert(argv.end(), args.begin(), args.end());
    const auto run = fvp::host::runProgram(argv, "");
    SCOPED_TRACE(args.front() + ": " + run.stderr_text);
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_NE(run.stderr_text.find("'" + out + "': in use by another fvp (" + holder + ")"),
              std::string::npos);
    std::vector<std::string> written;
    for (const auto& e : fs::directory_iterator(dir / "out"))
      if (e.path().filename() != ".fvp.lock") written.push_back(e.path().string());
    EXPECT_EQ(written, std::vector<std::string>{});
  }
  ::close(fd);
  // Released: the next writer takes the lock, and removes the lock file when it is done.
  const auto run = fvp::host::runProgram(
      {kFvp, "experiment", "--planners", "fvp", "--trials", "2", "--shard", "3/4", "--out", out},
      "");
  EXPECT_EQ(run.exit_code, 0) << run.stderr_text;
  EXPECT_FALSE(fs::exists(dir / "out" / ".fvp.lock"));
}

// A write failure after the trial ran costs extras only: result.json (written first) and
// the experiment's trials.jsonl line are kept, the cause is named (here EFBIG from a file
// size limit, as ENOSPC from a full disk: "File too large", not "the writer reported an
// error"), and the command fails, so that a script notices.
TEST(Outputs, AFailedWriteOfAnExtraKeepsTheTrial) {
  const fs::path dir = fs::path(::testing::TempDir()) / "fvp_bad_inputs_file_limit";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // 192 KiB: result.json of a one-view trial fits, fine.ot and the clouds do not.
  const rlim_t limit = 192 << 10;
  const auto run = runLimited({kFvp, "run", "--seed", "3", "--max-views", "1", "--clock", "fixed",
                               "--backend", "cpu", "--out", p(dir / "run")},
                              RLIMIT_FSIZE, limit);
  SCOPED_TRACE(run.stderr_text);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.stderr_text.find("File too large"), std::string::npos);
  EXPECT_EQ(run.stderr_text.find("the writer reported an error"), std::string::npos);
  EXPECT_NE(run.stderr_text.find("result.json holds the trial"), std::string::npos);
  std::ifstream in(dir / "run" / "result.json");
  const nlohmann::json result = nlohmann::json::parse(in);
  ASSERT_TRUE(result.contains("unwritten_outputs"));
  EXPECT_FALSE(result["unwritten_outputs"].empty());
  EXPECT_TRUE(result.contains("fruitlets"));
  EXPECT_EQ(temporaries(dir), std::vector<std::string>{});

  const auto exp =
      runLimited({kFvp, "experiment", "--planners", "fvp", "--trials", "1", "--max-views", "1",
                  "--clock", "fixed", "--backend", "cpu", "--out", p(dir / "exp")},
                 RLIMIT_FSIZE, limit);
  SCOPED_TRACE(exp.stderr_text);
  EXPECT_EQ(exp.exit_code, 0);
  EXPECT_NE(exp.stderr_text.find("not written"), std::string::npos);
  EXPECT_EQ(lines(dir / "exp" / "trials.jsonl").size(), 1u);
  EXPECT_EQ(temporaries(dir), std::vector<std::string>{});
}

// Memory asked for by a setting is estimated before it is allocated, against what the
// process may have (here an address-space limit of 4 GiB): the message names the setting.
TEST(Outputs, MemoryASettingAsksForIsCheckedFirst) {
#if defined(__SANITIZE_ADDRESS__)
  // The child runs under a 4 GiB address-space limit, and AddressSanitizer's shadow memory
  // alone reserves more: the sanitized fvp could not start.
  GTEST_SKIP() << "the address-space limit leaves no room for AddressSanitizer's shadow memory";
#endif
  const fs::path dir = fs::path(::testing::TempDir()) / "fvp_bad_inputs_memory";
  fs::remove_all(dir);
  // Ten views of 8192 x 8192 keep ~5 GiB for sizing: refused from camera.yaml alone.
  const std::string big = cameraYaml({{"width", "8192"},
                                      {"height", "8192"},
                                      {"fx", "7000"},
                                      {"fy", "7000"},
                                      {"cx", "4095.5"},
                                      {"cy", "4095.5"}});
  for (int i = 0; i < 10; ++i)
    writeText(dir / "set" / ("00" + std::to_string(i)) / "camera.yaml", big);
  const rlim_t limit = rlim_t{4} << 30;
  const auto size = runLimited(
      {kFvp, "size", "--captures", p(dir / "set"), "--backend", "cpu", "--out", p(dir / "out")},
      RLIMIT_AS, limit);
  EXPECT_EQ(size.exit_code, 1) << size.stderr_text;
  EXPECT_NE(size.stderr_text.find("10 captures (--captures"), std::string::npos)
      << size.stderr_text;
  EXPECT_NE(size.stderr_text.find("more than the 4.0 GiB available"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "out" / "fruitlets.json"));
  const auto traverse =
      runLimited({kFvp, "traverse", "--side-voxels", "1024", "--backend", "cpu"}, RLIMIT_AS, limit);
  EXPECT_EQ(traverse.exit_code, 1) << traverse.stderr_text;
  EXPECT_NE(traverse.stderr_text.find("traverse --side-voxels 1024"), std::string::npos)
      << traverse.stderr_text;
}

/// Starts fvp with stdout and stderr to log; returns its PID.
pid_t spawnFvp(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv = {kFvp};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> cargv;
  for (auto& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = -1;
  if (posix_spawn(&pid, kFvp, &actions, nullptr, cargv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

// SIGTERM ends an experiment cleanly: the trials that finished stay in trials.jsonl, no
// temporary is left, and the exit status is 128 + 15.
TEST(Signals, SigtermKeepsFinishedTrialsAndRemovesTemporaries) {
  const fs::path dir = fs::path(::testing::TempDir()) / "fvp_bad_inputs_sigterm";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // A temporary a killed run left: removed by the next writer of the directory.
  writeText(dir / "exp" / "trials" / "fvp-1" / "fine.ot.tmp-2147483-7", "stale");
  const pid_t pid = spawnFvp({"experiment", "--planners", "fvp", "--trials", "3", "--max-views",
                              "1", "--clock", "fixed", "--backend", "cpu", "--out", p(dir / "exp")},
                             dir / "log.txt");
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(5);
  while (lines(dir / "exp" / "trials.jsonl").empty() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ::kill(pid, SIGTERM);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  std::ifstream log_in(dir / "log.txt");
  const std::string log((std::istreambuf_iterator<char>(log_in)), std::istreambuf_iterator<char>());
  SCOPED_TRACE(log);
  ASSERT_TRUE(WIFEXITED(status)) << "a signal ended fvp";
  const std::vector<std::string> done = lines(dir / "exp" / "trials.jsonl");
  if (done.size() < 3) {  // stopped before the end (the usual case)
    EXPECT_EQ(WEXITSTATUS(status), 143);
    EXPECT_NE(log.find("interrupted by SIGTERM"), std::string::npos);
  }
  EXPECT_GE(done.size(), 1u);
  for (const std::string& line : done) EXPECT_TRUE(nlohmann::json::accept(line)) << line;
  EXPECT_EQ(temporaries(dir), std::vector<std::string>{});
  EXPECT_FALSE(fs::exists(dir / "exp" / ".fvp.lock"));
}

}  // namespace
