#include "fvp/host/perception/ply_io.h"

#include <bit>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "fvp/host/core/atomic_file.h"

namespace fvp::host {

static_assert(std::endian::native == std::endian::little,
              "PLY I/O writes the host's floats as binary_little_endian");

void writePlyPoints(const std::filesystem::path& path, const std::vector<Eigen::Vector3f>& points) {
  std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment fvp capture, world frame, metres\n"
      "element vertex " +
      std::to_string(points.size()) +
      "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  std::string bytes = header;
  const std::size_t offset = bytes.size();
  bytes.resize(offset + points.size() * 3 * sizeof(float));
  char* dst = bytes.data() + offset;
  for (const auto& p : points) {
    std::memcpy(dst, p.data(), 3 * sizeof(float));
    dst += 3 * sizeof(float);
  }
  writeFileAtomically(path, "point cloud (PLY)", bytes);
}

void writePlyColoredPoints(const std::filesystem::path& path,
                           const std::vector<Eigen::Vector3f>& points,
                           const std::vector<std::array<std::uint8_t, 3>>& colors_rgb,
                           const std::string& comment) {
  if (colors_rgb.size() != points.size())
    throw std::invalid_argument("writePlyColoredPoints: one colour per point expected");
  std::string bytes = "ply\nformat binary_little_endian 1.0\ncomment " + comment +
                      "\nelement vertex " + std::to_string(points.size()) +
                      "\nproperty float x\nproperty float y\nproperty float z\n"
                      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  const std::size_t offset = bytes.size();
  bytes.resize(offset + points.size() * (3 * sizeof(float) + 3));
  char* dst = bytes.data() + offset;
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::memcpy(dst, points[i].data(), 3 * sizeof(float));
    std::memcpy(dst + 3 * sizeof(float), colors_rgb[i].data(), 3);
    dst += 3 * sizeof(float) + 3;
  }
  writeFileAtomically(path, "coloured point cloud (PLY)", bytes);
}

void writePlyMesh(const std::filesystem::path& path, const std::vector<Eigen::Vector3f>& vertices,
                  const std::vector<std::array<std::uint32_t, 3>>& triangles,
                  const std::string& comment) {
  for (const auto& t : triangles)
    for (const std::uint32_t v : t)
      if (v >= vertices.size())
        throw std::invalid_argument("writePlyMesh: a triangle names a vertex that is not there");
  std::string bytes = "ply\nformat binary_little_endian 1.0\ncomment " + comment +
                      "\nelement vertex " + std::to_string(vertices.size()) +
                      "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                      std::to_string(triangles.size()) +
                      "\nproperty list uchar uint vertex_indices\nend_header\n";
  const std::size_t offset = bytes.size();
  constexpr std::size_t kFaceBytes = 1 + 3 * sizeof(std::uint32_t);
  bytes.resize(offset + vertices.size() * 3 * sizeof(float) + triangles.size() * kFaceBytes);
  char* dst = bytes.data() + offset;
  for (const auto& p : vertices) {
    std::memcpy(dst, p.data(), 3 * sizeof(float));
    dst += 3 * sizeof(float);
  }
  for (const auto& t : triangles) {
    *dst = 3;
    std::memcpy(dst + 1, t.data(), 3 * sizeof(std::uint32_t));
    dst += kFaceBytes;
  }
  writeFileAtomically(path, "triangle mesh (PLY)", bytes);
}

std::vector<Eigen::Vector3f> readPlyPoints(const std::filesystem::path& path) {
  const std::string name = path.string();
  auto fail = [&](const std::string& field, const std::string& expected) -> void {
    throw std::runtime_error(name + ": " + field + ": expected " + expected);
  };
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(name + ": cannot open");
  std::string line;
  std::getline(in, line);
  if (line != "ply") fail("magic", "'ply' on the first line");
  std::size_t vertices = 0;
  bool have_vertex = false, in_vertex = false, format_ok = false;
  int prop_index = 0, x_index = -1, y_index = -1, z_index = -1;
  std::vector<int> prop_sizes;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "end_header") break;
    if (word == "comment" || word == "obj_info" || word.empty()) continue;
    if (word == "format") {
      std::string fmt, version;
      ls >> fmt >> version;
      if (fmt != "binary_little_endian") fail("format", "binary_little_endian, got '" + fmt + "'");
      format_ok = true;
    } else if (word == "element") {
      std::string el, rest;
      long long n = -1;
      ls >> el >> n;
      if (!ls || (ls >> rest)) fail("element " + el, "'element <name> <count>'");
      in_vertex = el == "vertex";
      // Other elements' data would precede or follow the vertices unaccounted for.
      if (!in_vertex) fail("element " + el, "only a vertex element");
      if (in_vertex) {
        if (have_vertex) fail("element vertex", "a single vertex element");
        if (n < 0) fail("element vertex", "a non-negative count");
        if (prop_index != 0 || !prop_sizes.empty()) fail("element vertex", "the first element");
        vertices = static_cast<std::size_t>(n);
        have_vertex = true;
      }
    } else if (word == "property" && in_vertex) {
      std::string type, prop;
      ls >> type >> prop;
      int size = 0;
      if (type == "float" || type == "float32" || type == "int" || type == "int32" ||
          type == "uint" || type == "uint32")
        size = 4;
      else if (type == "double" || type == "float64")
        size = 8;
      else if (type == "uchar" || type == "uint8" || type == "char" || type == "int8")
        size = 1;
      else if (type == "short" || type == "ushort" || type == "int16" || type == "uint16")
        size = 2;
      else
        fail("property " + prop, "a scalar type, got '" + type + "'");
      const bool is_float = type == "float" || type == "float32";
      if (prop == "x" || prop == "y" || prop == "z") {
        if (!is_float) fail("property " + prop, "type float, got '" + type + "'");
        (prop == "x" ? x_index : prop == "y" ? y_index : z_index) = prop_index;
      }
      prop_sizes.push_back(size);
      ++prop_index;
    }
  }
  if (line != "end_header") fail("header", "an 'end_header' line");
  if (!format_ok) fail("format", "a 'format binary_little_endian 1.0' line");
  if (!have_vertex) fail("element vertex", "a vertex element");
  if (x_index < 0 || y_index < 0 || z_index < 0)
    fail("vertex properties", "float properties x, y and z");
  std::vector<int> offsets(prop_sizes.size());
  int stride = 0;
  for (std::size_t i = 0; i < prop_sizes.size(); ++i) {
    offsets[i] = stride;
    stride += prop_sizes[i];
  }
  // The count must fit the bytes that follow the header before anything is allocated.
  const std::streampos data_start = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streamoff available = in.tellg() - data_start;
  in.seekg(data_start);
  if (stride <= 0 || available < 0 ||
      vertices > static_cast<std::size_t>(available) / static_cast<std::size_t>(stride))
    fail("vertex data", std::to_string(vertices) + " vertices of " + std::to_string(stride) +
                            " bytes, the file is truncated");
  std::vector<char> data(vertices * stride);
  in.read(data.data(), static_cast<std::streamsize>(data.size()));
  if (static_cast<std::size_t>(in.gcount()) != data.size())
    fail("vertex data", std::to_string(vertices) + " vertices of " + std::to_string(stride) +
                            " bytes, the file is truncated");
  std::vector<Eigen::Vector3f> points(vertices);
  for (std::size_t i = 0; i < vertices; ++i) {
    const char* rec = data.data() + i * stride;
    std::memcpy(&points[i].x(), rec + offsets[x_index], 4);
    std::memcpy(&points[i].y(), rec + offsets[y_index], 4);
    std::memcpy(&points[i].z(), rec + offsets[z_index], 4);
  }
  return points;
}

}  // namespace fvp::host
