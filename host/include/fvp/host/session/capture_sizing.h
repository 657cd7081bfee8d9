// `fvp size`: the sizing pipeline on stored captures (docs/capture-format.md), from the
// simulator or a real robot: every capture directory of a set, in name order, through the
// per-view mapping session (perception, Cluster Region from the AprilTag, maps, TSDF), then
// the sizing chain; scored against ground_truth.json when the set has one.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/sizing/fruitlet_sizer.h"

namespace fvp::accel {
class Backend;
}

namespace fvp::host {

struct CaptureSizingOptions {
  /// The tag, the Cluster Region (from the tag, or explicit) and segmentation thresholds.
  PerceptionConfig perception;
  sizing::SizingEstimator estimator = sizing::SizingEstimator::kOurs;
  std::string engine = "grid";    ///< map engine (grid needs backend)
  std::filesystem::path out_dir;  ///< fruitlets.json, surface.ply, mesh.ply, clusters.ply
  /// Called with each warning as it happens; every warning is also in the result's
  /// "warnings" list.
  std::function<void(const std::string&)> on_warning;
};

/// The capture directories of a set: dir itself when it holds camera.yaml, else its
/// subdirectories that do, sorted by name. Throws std::runtime_error naming the directory
/// when there is none, when dir holds camera.yaml and capture subdirectories too (which one
/// was meant?), and when a subdirectory holds capture files but no camera.yaml (an
/// incomplete capture: writeCapture writes camera.yaml last). Other subdirectories are
/// skipped and reported through `skipped`.
std::vector<std::filesystem::path> listCaptures(const std::filesystem::path& dir,
                                                std::vector<std::string>* skipped = nullptr);

/// Sizes the set and writes fruitlets.json (centres, sizes, per-image sizes, estimator,
/// counted events, warnings; with ground truth: the match, MAE and MAPE of both
/// estimators), then surface.ply, mesh.ply and clusters.ply into options.out_dir, which is
/// checked (and cleared of those files) before the first capture is read. Returns
/// fruitlets.json's object.
nlohmann::json sizeCaptureSet(const std::filesystem::path& captures_dir,
                              const CaptureSizingOptions& options, accel::Backend* backend);

}  // namespace fvp::host
