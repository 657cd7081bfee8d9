// Binary little-endian PLY point clouds (vertex element, float x y z), as read by
// MeshLab, CloudCompare and Open3D.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <vector>

namespace fvp::host {

/// Writes to a temporary file in the same directory and renames it into place.
void writePlyPoints(const std::filesystem::path& path, const std::vector<Eigen::Vector3f>& points);
/// Throws std::runtime_error naming the file and what was expected. Accepts extra vertex
/// properties (skipped) as long as x, y, z are floats.
std::vector<Eigen::Vector3f> readPlyPoints(const std::filesystem::path& path);

}  // namespace fvp::host
