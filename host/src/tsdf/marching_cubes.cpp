#include "fvp/host/tsdf/marching_cubes.h"

#include <Eigen/Geometry>
#include <stdexcept>
#include <unordered_map>

namespace fvp::host::tsdf {
namespace {

using CaseTable = std::array<std::vector<std::vector<int>>, 256>;

int edgeBetween(int a, int b) {
  const int diff = a ^ b;
  const int axis = diff == 1 ? 0 : diff == 2 ? 1 : 2;
  const int low = a < b ? a : b;
  // The j-th corner with bit `axis` clear: squeeze that bit out of the corner index.
  const int j = ((low >> (axis + 1)) << axis) | (low & ((1 << axis) - 1));
  return axis * 4 + j;
}

CaseTable buildCases() {
  CaseTable table;
  for (int config = 0; config < 256; ++config) {
    const auto inside = [config](int corner) { return ((config >> corner) & 1) != 0; };
    // Each crossing edge lies on two faces, so it gets exactly two neighbours.
    std::array<std::vector<int>, MarchingCubes::kEdges> links;
    for (int axis = 0; axis < 3; ++axis) {
      const int b = (axis + 1) % 3, c = (axis + 2) % 3;
      for (int side = 0; side < 2; ++side) {
        std::array<int, 4> q;  // the face's corners in cyclic order
        const std::array<std::array<int, 2>, 4> bc = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
        for (int k = 0; k < 4; ++k) q[k] = (side << axis) | (bc[k][0] << b) | (bc[k][1] << c);
        std::array<int, 4> e;  // e[k] joins q[k] and q[k + 1]
        for (int k = 0; k < 4; ++k) e[k] = edgeBetween(q[k], q[(k + 1) % 4]);
        std::vector<int> crossing;
        for (int k = 0; k < 4; ++k)
          if (inside(q[k]) != inside(q[(k + 1) % 4])) crossing.push_back(k);
        const auto join = [&links](int x, int y) {
          links[x].push_back(y);
          links[y].push_back(x);
        };
        if (crossing.size() == 2) {
          join(e[crossing[0]], e[crossing[1]]);
        } else if (crossing.size() == 4) {
          // Ambiguous face: cut off each inside corner on its own.
          for (int k = 0; k < 4; ++k)
            if (inside(q[k])) join(e[(k + 3) % 4], e[k]);
        }
      }
    }
    std::array<bool, MarchingCubes::kEdges> used{};
    for (int start = 0; start < MarchingCubes::kEdges; ++start) {
      if (used[start] || links[start].empty()) continue;
      std::vector<int> cycle;
      int previous = -1, current = start;
      do {
        cycle.push_back(current);
        used[current] = true;
        const int next = links[current][0] != previous ? links[current][0] : links[current][1];
        previous = current;
        current = next;
      } while (current != start);
      table[config].push_back(std::move(cycle));
    }
  }
  return table;
}

const CaseTable& cases() {
  static const CaseTable table = buildCases();
  return table;
}

}  // namespace

std::array<int, 2> MarchingCubes::edgeCorners(int edge) {
  const int axis = edge / 4, j = edge % 4;
  // Re-insert a zero bit at position `axis` into j.
  const int low = ((j >> axis) << (axis + 1)) | (j & ((1 << axis) - 1));
  return {low, low | (1 << axis)};
}

const std::vector<std::vector<int>>& MarchingCubes::cycles(int configuration) {
  if (configuration < 0 || configuration > 255)
    throw std::invalid_argument("MarchingCubes::cycles: configuration must be in [0, 255]");
  return cases()[configuration];
}

TriangleMesh MarchingCubes::extract(const std::vector<std::array<int, 3>>& cube_origins,
                                    const Sampler& sample, const Eigen::Vector3d& origin_m,
                                    double voxel_size_m) {
  constexpr int kMaxIndex = 1 << 20;
  TriangleMesh mesh;
  // A vertex per cut edge of the grid, shared by the (up to four) cubes around that edge.
  std::unordered_map<std::uint64_t, std::uint32_t> vertex_of_edge;
  for (const auto& g : cube_origins) {
    for (int axis = 0; axis < 3; ++axis)
      if (g[axis] < 0 || g[axis] + 1 >= kMaxIndex)
        throw std::invalid_argument("MarchingCubes::extract: cube index outside [0, 2^20 - 1)");
    const auto cornerOf = [&g](int i) -> std::array<int, 3> {
      return {g[0] + (i & 1), g[1] + ((i >> 1) & 1), g[2] + ((i >> 2) & 1)};
    };
    std::array<float, kCorners> d;
    int config = 0;
    bool observed = true;
    for (int i = 0; i < kCorners && observed; ++i) {
      observed = sample(cornerOf(i), d[i]);
      if (observed && d[i] < 0.0f) config |= 1 << i;
    }
    if (!observed || config == 0 || config == 255) continue;

    const auto cornerPosition = [&](int i) {
      const std::array<int, 3> c = cornerOf(i);
      return Eigen::Vector3d(c[0], c[1], c[2]);
    };
    const auto vertexOn = [&](int edge) {
      const auto [a, b] = edgeCorners(edge);
      const std::array<int, 3> low = cornerOf(a);
      const std::uint64_t key =
          (((std::uint64_t(low[0]) << 40) | (std::uint64_t(low[1]) << 20) | std::uint64_t(low[2]))
           << 2) |
          std::uint64_t(edge / 4);
      const auto [it, added] =
          vertex_of_edge.try_emplace(key, static_cast<std::uint32_t>(mesh.vertices_m.size()));
      if (added) {
        const double t = d[a] / (d[a] - d[b]);
        const Eigen::Vector3d p = cornerPosition(a) + t * (cornerPosition(b) - cornerPosition(a));
        mesh.vertices_m.push_back((origin_m + voxel_size_m * p).cast<float>());
      }
      return it->second;
    };
    for (const std::vector<int>& cycle : cycles(config)) {
      std::vector<std::uint32_t> ids;
      // Outward for this cycle: along its edges, from the inside corner to the outside one.
      Eigen::Vector3d outward = Eigen::Vector3d::Zero();
      for (const int edge : cycle) {
        ids.push_back(vertexOn(edge));
        const auto [a, b] = edgeCorners(edge);
        outward += (d[a] < 0.0f ? 1.0 : -1.0) * (cornerPosition(b) - cornerPosition(a));
      }
      // Newell's normal of the cycle (about its first vertex) decides its winding.
      const Eigen::Vector3d p0 = mesh.vertices_m[ids[0]].cast<double>();
      Eigen::Vector3d normal = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < ids.size(); ++k) {
        const Eigen::Vector3d p = mesh.vertices_m[ids[k]].cast<double>() - p0;
        const Eigen::Vector3d q = mesh.vertices_m[ids[(k + 1) % ids.size()]].cast<double>() - p0;
        normal += p.cross(q);
      }
      const bool flip = normal.dot(outward) < 0.0;
      for (std::size_t k = 1; k + 1 < ids.size(); ++k) {
        if (flip)
          mesh.triangles.push_back({ids[0], ids[k + 1], ids[k]});
        else
          mesh.triangles.push_back({ids[0], ids[k], ids[k + 1]});
      }
    }
  }
  return mesh;
}

}  // namespace fvp::host::tsdf
