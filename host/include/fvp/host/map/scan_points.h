// The one preparation of a view's clouds for both map engines, so that they cut and count
// points identically (docs/design.md section 5): the grid engine uploads the result to its scan
// kernels as is, the octomap engine walks its rays with computeRayKeys.
#pragma once

#include <vector>

#include "fvp/accel/kernel_types.h"
#include "fvp/host/core/labeled_clouds.h"
#include "fvp/host/map/scan_stats.h"

namespace fvp::host::map {

/// Ray end points of one view, ROI points first, then the others. Every input point is
/// counted in stats.points. Non-finite points are skipped and counted (skipped_invalid).
/// Points farther than max_range_m from the sensor end their ray at that range with no hit
/// (flags 0; OctoMap's maxrange) and are counted (truncated); range and cut are computed in
/// double, the end stored in float. The rest are hits (FVP_POINT_HIT, with FVP_POINT_ROI
/// for ROI points).
std::vector<accel::ScanPoint> prepareScanPoints(const LabeledClouds& clouds, double max_range_m,
                                                ScanStats& stats);

}  // namespace fvp::host::map
