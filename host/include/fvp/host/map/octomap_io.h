// OctoMap files of the maps (format and ROI encoding: docs/maps.md). Shared by both map
// engines: the grid engine builds the same trees from its voxels and writes them here.
//
// - Coarse map: a .bt file (octomap::OcTree::writeBinaryConst): occupancy as OctoMap's
//   binary format (free / occupied / unknown per voxel); any OctoMap tool reads it.
// - Fine map: an .ot file holding an octomap::ColorOcTree, a type OctoMap's library and
//   tools (convert_octree, octovis) read: occupancy log-odds exact, the ROI log-odds in the
//   colour (see encodeRoiColor).
// Every file is written to a temporary file in the same directory and renamed into place,
// so a reader never sees half a file.
#pragma once

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <filesystem>
#include <memory>

#include "fvp/host/map/roi_octree.h"

namespace fvp::host::map {

/// Colour of ROI voxels' red channel (visible in octovis) and of all other voxels'.
inline constexpr std::uint8_t kRoiRed = 255;
inline constexpr std::uint8_t kNonRoiRed = 128;
/// ROI log-odds fixed point in the green (high byte) and blue (low byte) channels:
/// q = round(l * kRoiColorScale) + kRoiColorOffset, offset binary, |l| < 8 representable.
inline constexpr float kRoiColorScale = 4096.0f;
inline constexpr int kRoiColorOffset = 32768;

/// ROI log-odds -> colour. The rounding keeps the sign class: l > 0 (ROI) never decodes to
/// <= 0 and l <= 0 never to > 0, so the ROI flag survives exactly. Values clamp to +-8.
octomap::ColorOcTreeNode::Color encodeRoiColor(float roi_log_odds);
/// Colour -> ROI log-odds (within 1/8192 of the encoded value, sign class exact).
float decodeRoiColor(const octomap::ColorOcTreeNode::Color& color);

/// Coarse map -> .bt (atomically). Throws std::runtime_error naming the file on failure.
void writeCoarseBt(const octomap::OcTree& tree, const std::filesystem::path& bt_path);
/// Resolutions readCoarseBt accepts (metres): OctoMap's 16-bit keys stay well-scaled.
inline constexpr double kMinBtResolutionM = 1e-6;
inline constexpr double kMaxBtResolutionM = 1e3;
/// .bt -> OcTree. Throws std::runtime_error naming the file when it is not a readable .bt:
/// the header (id, size, res in [kMinBtResolutionM, kMaxBtResolutionM]) and the node data
/// are checked before OctoMap reads them (the data must end with the tree, hold as many
/// nodes as the header says and no inner node below the tree's depth of 16).
std::unique_ptr<octomap::OcTree> readCoarseBt(const std::filesystem::path& bt_path);

/// The fine tree as the ColorOcTree written to .ot files: same node structure, occupancy
/// log-odds copied, ROI log-odds encoded in the colour.
std::unique_ptr<octomap::ColorOcTree> toColorOcTree(const RoiOcTree& tree);
/// The inverse of toColorOcTree (ROI log-odds decoded from the colour).
std::unique_ptr<RoiOcTree> fromColorOcTree(const octomap::ColorOcTree& tree);

/// Fine map -> .ot holding a ColorOcTree (atomically). Throws std::runtime_error on failure.
void writeFineOt(const RoiOcTree& tree, const std::filesystem::path& ot_path);
/// .ot -> RoiOcTree. Accepts a ColorOcTree written by writeFineOt (or by OctoMap's tools
/// from one, e.g. convert_octree) and a native RoiOcTree .ot. Throws std::runtime_error
/// naming the file otherwise.
std::unique_ptr<RoiOcTree> readFineOt(const std::filesystem::path& ot_path);

}  // namespace fvp::host::map
