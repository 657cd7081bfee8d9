// `fvp size`: the sizing pipeline on stored captures (docs/capture-format.md), from the
// simulator or a real robot: every capture directory of a set, in name order, through the
// per-view mapping session (perception, Cluster Region from the AprilTag, maps, TSDF), then
// the sizing chain; scored against ground_truth.json when the set has one.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "fvp/host/sizing/fruitlet_sizer.h"

namespace fvp::accel {
class Backend;
}

namespace fvp::host {

struct CaptureSizingOptions {
  sizing::SizingEstimator estimator = sizing::SizingEstimator::kOurs;
  std::string engine = "grid";    ///< map engine (grid needs backend)
  std::filesystem::path out_dir;  ///< fruitlets.json, surface.ply, clusters.ply
};

/// The capture directories of a set: dir itself when it holds camera.yaml, else its
/// subdirectories that do, sorted by name. Throws std::runtime_error naming dir when none.
std::vector<std::filesystem::path> listCaptures(const std::filesystem::path& dir);

/// Sizes the set and writes fruitlets.json (centres, sizes, per-image sizes, estimator,
/// counted events; with ground truth: the match, MAE and MAPE of both estimators),
/// surface.ply and clusters.ply into options.out_dir. Returns fruitlets.json's object.
nlohmann::json sizeCaptureSet(const std::filesystem::path& captures_dir,
                              const CaptureSizingOptions& options, accel::Backend* backend);

}  // namespace fvp::host
