// The library's kernels (kernels/*.cl, shaders/*.comp, CPU loops in accel/src/kernels/).
// Run one with Backend::run(kernel, params, {buffers in binding order}).
#pragma once

#include "fvp/accel/kernel.h"
#include "fvp/accel/kernel_types.h"

namespace fvp::accel::kernels {

/// Batched voxel ray traversal over a dense grid (fvp_traverse_ray). Bindings: rays
/// (ray_count Ray), occupancy and field (voxelCount(grid) float each), results (ray_count
/// RayResult).
Kernel<TraverseParams> rayTraverse();

/// Scan integration, mark pass (fvp_scan_mark_point): one item per point. Bindings: points
/// (point_count ScanPoint), brick_table (brick_count int), marks (slot_count / 4 uint,
/// zero before the first scan; the update pass leaves them zero), missing (brick_count + 1
/// uint): voxels in unallocated bricks set missing[brick] and missing[brick_count].
Kernel<ScanParams> scanMark();

/// Scan integration, update pass (fvp_scan_update_chunk): one item per 64 slots. Bindings:
/// marks (slot_count / 4 uint), occupancy (slot_count float), roi (slot_count float, unused
/// unless has_roi), updated (1 uint; the number of updated voxels is added to it),
/// changed_bricks (slot_count / 512 uint: set to 1 for each brick with an updated voxel).
Kernel<UpdateParams> scanUpdate();

/// One pass (params.axis) of the ROI distance field (fvp_roi_distance_line): one item per
/// line of 8 voxels along the axis in the work bricks (64 a brick). Bindings: brick_coords (3 int
/// per brick), brick_table, roi (axis 0), sq_in (axes 1 and 2), sq_out (axes 0 and 1) as slot_count
/// uint, distance_vox (axis 2, slot_count float), work_bricks (work_brick_count uint allocation
/// indices).
Kernel<EdtParams> roiDistance();

/// Frontier extraction (fvp_frontier_append): one item per slot. Bindings: brick_coords,
/// brick_table, occupancy, roi (slot_count float), frontiers (capacity Frontier, filled in
/// any order), count (1 uint: the total found, which may exceed the capacity).
Kernel<FrontierParams> frontier();

/// Information gain of ray segments over the planner's map snapshot (fvp_info_gain): one
/// item per segment. Bindings: segments (segment_count GainSegment), fine_codes
/// (gainFineWords(fine) uint), coarse_occupied (gainCoarseWords(coarse) uint), results
/// (segment_count GainResultRaw).
Kernel<GainParams> infoGain();

/// Projective TSDF integration of one view (fvp_tsdf): one item per voxel of the bricks to
/// update. Bindings: brick_coords (3 int per allocated brick), update_bricks (update_bricks
/// uint: allocation indices), depth_m (width_px * height_px float, 0 = no ROI depth),
/// distance and weight (512 float per allocated brick, read and written).
Kernel<TsdfParams> tsdfIntegrate();

/// Coarse-guided semi-global matching of a stereo pair's band (kernels/fvp_stereo.h), four
/// dispatches in order. stereo_census: one item per census pixel (the band in the left
/// image, then the right image's columns the band may match, fvp_stereo_right_x0 to the
/// band's end). Bindings: grey (both whole images, left first, four 8-bit pixels a uint),
/// census (two uint a census pixel).
Kernel<StereoParams> stereoCensus();
/// stereo_cost: one item per band pixel. Bindings: census, coarse_disparity (the guide:
/// coarse_width_px * coarse_height_px int, disparity * 16, <= 0 none), windows (one uint a
/// band pixel), costs (4 uint a band pixel).
Kernel<StereoParams> stereoCost();
/// stereo_aggregate: one item per line of params.path_family (run families 0..3 in turn,
/// first_family = 1 for the first). Bindings: windows, costs, sums (8 uint a band pixel).
Kernel<StereoParams> stereoAggregate();
/// stereo_select: one item per band row. Bindings: windows, sums, right_best (scratch:
/// band_height_px * (band_width_px + max_disparity_px) uint), disparity (one int a band
/// pixel: disparity * 16, or FVP_STEREO_INVALID / _OUTSIDE / _UNGUIDED).
Kernel<StereoParams> stereoSelect();

}  // namespace fvp::accel::kernels
