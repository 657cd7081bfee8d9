// `fvp map`: map a simulated world from a sequence of views around the cluster and export
// the coarse (.bt) and fine (.ot) maps that OctoMap's tools read.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/accel/backend.h"
#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/simulated_mapping.h"

namespace fvp::apps {

void addMapCommand(CLI::App& app) {
  struct Options {
    std::uint64_t seed = 1;
    std::string world_file;
    std::string map_config_file;
    int views = 5;
    double arc_deg = 90.0;
    std::string engine = "grid";
    accel::BackendChoice backend = accel::BackendChoice::kAuto;
    std::string out;
  };
  auto opt = optionStorage<Options>();
  auto* cmd = app.add_subcommand(
      "map",
      "Map a simulated world from views orbiting the cluster; write coarse.bt, fine.ot "
      "and map.json to --out");
  cmd->add_option("--seed", opt->seed, "world seed")
      ->check(decimalUnsigned())
      ->capture_default_str();
  cmd->add_option("--world", opt->world_file, "world config YAML (default: built-in defaults)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--map-config", opt->map_config_file,
                  "map config YAML (keys and defaults: host/config/map_default.yaml)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--views", opt->views, "number of views")
      ->check(decimalUnsigned())
      ->check(CLI::Range(1, 360))
      ->capture_default_str();
  cmd->add_option("--arc-deg", opt->arc_deg, "arc the views span around the cluster")
      ->check(finiteNumber())
      ->check(CLI::Range(0.0, 360.0))
      ->capture_default_str();
  cmd->add_option("--engine", opt->engine, "map engine: grid | octomap")
      ->check(CLI::IsMember(mapEngineNames()))
      ->capture_default_str();
  addBackendOption(cmd, opt->backend, "compute backend for the grid engine");
  cmd->add_option("--out", opt->out, "output directory")->required()->check(nonEmptyPath());
  FVP_ON_RUN(cmd, [opt] {
    using robot::sim::WorldConfig;
    host::prepareOutputDirectory(opt->out, "--out");
    const host::OutputDirectoryLock lock(opt->out, "--out");
    host::removeStaleOutputs(opt->out, {"coarse.bt", "fine.ot", "map.json"});
    const WorldConfig config =
        opt->world_file.empty() ? WorldConfig{} : WorldConfig::fromYamlFile(opt->world_file);
    const auto world = robot::sim::World::generate(config, opt->seed);
    std::unique_ptr<accel::Backend> backend;
    if (host::map::mapEngineNeedsBackend(opt->engine)) backend = accel::createBackend(opt->backend);
    robot::sim::SimulatedMappingOptions options;
    options.engine = opt->engine;
    if (!opt->map_config_file.empty())
      options.map = host::map::MapConfig::fromYamlFile(opt->map_config_file);
    const auto poses = robot::sim::orbitViews(world, opt->views, opt->arc_deg);
    const auto result = robot::sim::mapSimulatedViews(world, poses, options, backend.get());

    std::cout << "world          seed " << opt->seed << ", " << world.fruitlets().size()
              << " fruitlets\n"
              << "engine         " << opt->engine;
    if (backend)
      std::cout << " on " << accel::toString(backend->kind()) << " (" << backend->deviceName()
                << ")";
    std::cout << "\n\n view  tag  ROI pts  other pts  render ms  perceive ms  map ms  coarse upd  "
                 "fine upd\n";
    nlohmann::ordered_json views = nlohmann::ordered_json::array();
    for (std::size_t i = 0; i < result.views.size(); ++i) {
      const auto& v = result.views[i];
      std::cout << std::setw(5) << i << std::setw(5) << (v.tag_detected ? "yes" : "no")
                << std::setw(9) << v.roi_points << std::setw(11) << v.other_points << std::setw(11)
                << std::fixed << std::setprecision(0) << v.render_s * 1e3 << std::setw(13)
                << v.perceive_s * 1e3 << std::setw(8) << v.scan.seconds * 1e3 << std::setw(12)
                << v.scan.coarse_voxels_updated << std::setw(10) << v.scan.fine_voxels_updated
                << "\n";
      views.push_back({{"tag_detected", v.tag_detected},
                       {"roi_points", v.roi_points},
                       {"other_points", v.other_points},
                       {"render_s", v.render_s},
                       {"perceive_s", v.perceive_s},
                       {"map_s", v.scan.seconds},
                       {"skipped_invalid", v.scan.skipped_invalid},
                       {"truncated", v.scan.truncated},
                       {"coarse_voxels_updated", v.scan.coarse_voxels_updated},
                       {"fine_voxels_updated", v.scan.fine_voxels_updated}});
    }
    if (!result.map)
      throw std::runtime_error("no view detected the AprilTag: no Cluster Region, no map");
    const std::filesystem::path out(opt->out);
    std::filesystem::create_directories(out);
    result.map->exportCoarse(out / "coarse.bt");
    result.map->exportFine(out / "fine.ot");
    const auto& r = *result.region;
    nlohmann::ordered_json summary = {
        {"seed", opt->seed},
        {"engine", opt->engine},
        {"backend", backend ? std::string(accel::toString(backend->kind())) : "none"},
        {"cluster_region",
         {{"center_m", {r.center_m().x(), r.center_m().y(), r.center_m().z()}},
          {"radius_m", r.radius_m()}}},
        {"views", views}};
    host::writeFileAtomically(out / "map.json", "map summary", summary.dump(2) + "\n");
    std::cout << "\ncluster region centre (" << std::setprecision(4) << r.center_m().x() << ", "
              << r.center_m().y() << ", " << r.center_m().z() << "), radius " << r.radius_m()
              << " m\n"
              << "wrote          " << (out / "coarse.bt").string() << ", "
              << (out / "fine.ot").string() << ", " << (out / "map.json").string() << "\n";
  });
}

}  // namespace fvp::apps
