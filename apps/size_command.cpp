// `fvp size`: the sizing pipeline on stored captures (docs/capture-format.md, docs/sizing.md).
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/accel/backend.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/nbv/run_fields.h"
#include "fvp/host/report/capture_set_report.h"
#include "stereo_bag_files.h"

namespace fvp::apps {

void addSizeCommand(CLI::App& app) {
  struct Options {
    std::string captures, bag, bag_ns = "/stereo", world_frame = "world", out, sizing = "ours",
                               engine = "grid", config;
    accel::BackendChoice backend = accel::BackendChoice::kAuto;
    bool guided_stereo = host::nbv::run_fields::kDefaultGuidedStereo;  // as a trial sizes
  };
  auto opt = optionStorage<Options>();
  auto* cmd =
      app.add_subcommand("size",
                         "Size the fruitlets of a set of stored captures or of a ROS bag; write "
                         "fruitlets.json, "
                         "surface.ply, mesh.ply, "
                         "clusters.ply, viewer.html (the set in 3-D) and overlays/ to --out");
  auto* captures =
      cmd->add_option("--captures", opt->captures,
                      "a capture directory, or a directory of them (used in name order)");
  auto* bag = cmd->add_option("--bag", opt->bag,
                              "instead, a ROS bag of rectified stereo pairs, camera infos and tf "
                              "(docs/ros.md); its pairs are written to --out/captures and sized")
                  ->excludes(captures);
  captures->excludes(bag);
  cmd->add_option("--bag-ns", opt->bag_ns,
                  "the bag's stereo namespace: NS/{left,right}/image_rect_color, "
                  "NS/{left,right}/camera_info, NS/left/fruitlet_mask, NS/disparity (optional)")
      ->needs(bag)
      ->capture_default_str();
  cmd->add_option("--world-frame", opt->world_frame,
                  "the bag's tf frame that camera poses are looked up in")
      ->needs(bag)
      ->capture_default_str();
  cmd->add_option("--sizing", opt->sizing, "estimator: ours | paper (both are reported)")
      ->check(CLI::IsMember({"ours", "paper"}))
      ->capture_default_str();
  cmd->add_option("--engine", opt->engine, "map engine: grid | octomap")
      ->check(CLI::IsMember(mapEngineNames()))
      ->capture_default_str();
  addBackendOption(cmd, opt->backend,
                   "compute backend for the grid engine and the guided stereo pass");
  cmd->add_flag("--guided-stereo,!--no-guided-stereo", opt->guided_stereo,
                std::string(host::nbv::run_fields::kGuidedStereo.help) +
                    " (default: " + (opt->guided_stereo ? "on" : "off") + ", as in fvp run)");
  cmd->add_option("--config", opt->config,
                  "perception config YAML: the tag (family, id, size), the Cluster Region "
                  "(offset and radius, or an explicit centre) and HSV thresholds "
                  "(docs/capture-format.md)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", opt->out, "output directory")->required()->check(nonEmptyPath());
  FVP_ON_RUN(cmd, [opt] {
    host::PerceptionConfig perception;  // read first: a bad file fails before any work
    if (!opt->config.empty()) perception = host::PerceptionConfig::fromYamlFile(opt->config);
    perception.stereo.guided_fine = opt->guided_stereo;
    std::unique_ptr<accel::Backend> backend;
    if (host::map::mapEngineNeedsBackend(opt->engine) || opt->guided_stereo)
      backend = accel::createBackend(opt->backend);
    if (opt->captures.empty() == opt->bag.empty())
      throw std::invalid_argument("expected --captures DIR or --bag FILE");
    std::string captures_dir = opt->captures;
    if (!opt->bag.empty()) {
      host::prepareOutputDirectory(opt->out, "--out");
      captures_dir = (std::filesystem::path(opt->out) / "captures").string();
      extractBagCaptures(opt->bag, opt->bag_ns, opt->world_frame, captures_dir);
    }
    host::CaptureSizingOptions o;
    o.perception = perception;
    o.estimator = host::sizing::parseSizingEstimator(opt->sizing);
    o.engine = opt->engine;
    o.out_dir = opt->out;
    o.on_warning = [](const std::string& text) { std::cerr << "fvp: warning: " << text << "\n"; };
    const nlohmann::json r = host::sizeCaptureSet(captures_dir, o, backend.get());
    std::cout << r["captures"].size() << " captures, Cluster Region "
              << (r["cluster_region_found"].get<bool>()
                      ? "found"
                      : "NOT found (no tag seen, no region_center_m)")
              << ", " << r["sized_fruitlets"].size() << " fruitlets sized (" << opt->sizing
              << " estimator)\n"
              << std::fixed << std::setprecision(2);
    for (const auto& f : r["sized_fruitlets"])
      std::cout << "  centre (" << f["center_m"][0].get<double>() << ", "
                << f["center_m"][1].get<double>() << ", " << f["center_m"][2].get<double>()
                << ") m, size " << f["size_mm"].get<double>() << " mm from "
                << f["per_image"].size() << " images\n";
    if (r.contains("metrics")) {
      const auto& m = r["metrics"];
      std::cout << "against ground truth: match " << std::setprecision(1)
                << m["match_percent"].get<double>() << " %, MAE "
                << (m["mae_mm"].is_number() ? std::to_string(m["mae_mm"].get<double>()) : "-")
                << " mm, MAPE "
                << (m["mape_percent"].is_number() ? std::to_string(m["mape_percent"].get<double>())
                                                  : "-")
                << " %\n";
    }
    std::cout << "wrote " << opt->out
              << "/{fruitlets.json, surface.ply, mesh.ply, clusters.ply, viewer.html, overlays/}\n";
  });
}

}  // namespace fvp::apps
