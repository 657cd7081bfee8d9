// Binary little-endian PLY point clouds (vertex element, float x y z), as read by
// MeshLab, CloudCompare and Open3D.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace fvp::host {

/// Writes to a temporary file in the same directory and renames it into place.
void writePlyPoints(const std::filesystem::path& path, const std::vector<Eigen::Vector3f>& points);
/// Points with an 8-bit RGB colour each (binary little-endian PLY, atomic): clusters, candidate
/// viewpoints coloured by utility. colors_rgb.size() must equal points.size().
void writePlyColoredPoints(const std::filesystem::path& path,
                           const std::vector<Eigen::Vector3f>& points,
                           const std::vector<std::array<std::uint8_t, 3>>& colors_rgb,
                           const std::string& comment);

/// A triangle mesh (vertex element x y z, face element vertex_indices), binary, atomic.
void writePlyMesh(const std::filesystem::path& path, const std::vector<Eigen::Vector3f>& vertices,
                  const std::vector<std::array<std::uint32_t, 3>>& triangles,
                  const std::string& comment);

/// Throws std::runtime_error naming the file and what was expected. Accepts extra vertex
/// properties (skipped) as long as x, y, z are floats.
std::vector<Eigen::Vector3f> readPlyPoints(const std::filesystem::path& path);

}  // namespace fvp::host
