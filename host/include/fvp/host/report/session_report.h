// What a mapping session shows a person (docs/viewer.md): its part of the 3-D viewer's scene
// and the evidence report's overlays of the views that sized fruitlets. Shared by trials
// (one session per cluster) and `fvp size`.
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "fvp/host/report/viewer_scene.h"
#include "fvp/host/session/mapping_session.h"

namespace fvp::host {

/// The overlays of the session's views that count, each view in which a kept detection was
/// sized and, given a first_view_reason ("start view": a trial's), its first view, into
/// out_dir/overlays/NNN.jpg (NNN: first_view + the session's view). sizing is the session's sizing
/// as result.json holds it
/// ("sized_fruitlets", "unsupported_detections"). image_of gives a view's left image (any
/// size; empty: no overlay). Each overlay shows the crop around the Cluster Region. Returns
/// [{"view", "file", "why", "tag_detected"}].
nlohmann::json writeSessionOverlays(const MappingSession& session, const nlohmann::json& sizing,
                                    int first_view, std::optional<int> cluster,
                                    const std::function<cv::Mat(int view)>& image_of,
                                    const std::filesystem::path& out_dir,
                                    const std::optional<std::string>& first_view_reason = {});

/// The file of each view's overlay, from writeSessionOverlays' list: view -> "overlays/NNN.jpg".
std::map<int, std::string> overlayFileOfView(const nlohmann::json& overlays);

/// The session's occupied fine voxels, TSDF mesh, Cluster Region, tag and detections (views
/// numbered from first_view).
void addSessionToScene(report::ViewerScene& scene, const MappingSession& session,
                       const nlohmann::json& sizing, int first_view, std::optional<int> cluster);

}  // namespace fvp::host
