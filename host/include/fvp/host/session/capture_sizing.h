// Sizing on stored captures (docs/capture-format.md), from the simulator or a real robot:
// every capture directory of a set, in name order, through the per-view mapping session
// (perception, Cluster Region from the AprilTag, maps, TSDF), then the sizing chain. No
// scoring and no files here: `fvp size` scores against ground_truth.json and writes its
// outputs in the reporting layer (fvp/host/report/capture_set_report.h).
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/host/sizing/fruitlet_sizer.h"

namespace fvp::accel {
class Backend;
}

namespace fvp::host {

struct CaptureSizingOptions {
  /// The tag, the Cluster Region (from the tag, or explicit) and segmentation thresholds.
  PerceptionConfig perception;
  sizing::SizingEstimator estimator = sizing::SizingEstimator::kOurs;
  std::string engine = "grid";  ///< map engine (grid needs backend)
  /// Where sizeCaptureSet writes fruitlets.json, surface.ply, mesh.ply, clusters.ply
  /// (sizeCaptures writes nothing).
  std::filesystem::path out_dir;
  /// sizeCaptureSet calls it with each warning as it happens; every warning is also in the
  /// result's "warnings" list.
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

/// What sizeCaptures made of a set: the session (its maps, TSDF and views, in capture order),
/// its sizing, and what the captures said.
struct SizedCaptureSet {
  std::unique_ptr<MappingSession> session;
  sizing::SizingResult sized;
  /// Per capture: {"capture", "tag_detected", "fruitlet_pixels", "roi_points",
  /// "dropped_disparities"}.
  nlohmann::json captures = nlohmann::json::array();
  /// The first ground_truth.json among the captures and its path; empty when none has one
  /// (the session reads it, the reporting layer scores against it).
  std::string ground_truth_json, ground_truth_source;
};

/// The views of these captures must fit in the memory there is: throws (checkMemoryFor)
/// before any view is read.
void checkCaptureSetFitsInMemory(const std::vector<std::filesystem::path>& dirs);

/// Reads the captures in order through one mapping session (TSDF on) and sizes the fruitlets
/// with options' estimator. Each warning (a capture without fruitlet pixels, no tag seen) goes
/// to warn as it happens.
SizedCaptureSet sizeCaptures(const std::vector<std::filesystem::path>& dirs,
                             const CaptureSizingOptions& options, accel::Backend* backend,
                             const std::function<void(const std::string&)>& warn);

}  // namespace fvp::host
