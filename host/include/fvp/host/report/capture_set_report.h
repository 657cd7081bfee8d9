// `fvp size`: a capture set sized (sizeCaptures, fvp/host/session/capture_sizing.h), scored
// against ground_truth.json when the set has one, and written out for a person (fruitlets.json,
// the clouds, the overlays and viewer.html). Here, above the session, so that the sizing a
// robot runs links no ground-truth scoring and no viewer.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "fvp/host/session/capture_sizing.h"

namespace fvp::accel {
class Backend;
}

namespace fvp::host {

/// Sizes the set and writes fruitlets.json (centres, sizes, per-image sizes, estimator,
/// counted events, warnings; with ground truth: the match, MAE and MAPE of both
/// estimators), then surface.ply, mesh.ply and clusters.ply into options.out_dir, which is
/// checked (and cleared of those files) before the first capture is read. Returns
/// fruitlets.json's object.
nlohmann::json sizeCaptureSet(const std::filesystem::path& captures_dir,
                              const CaptureSizingOptions& options, accel::Backend* backend);

}  // namespace fvp::host
