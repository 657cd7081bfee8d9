#include "fvp/host/map/occupied_voxel_scene.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "fvp/accel/embree_check.h"

namespace fvp::host::map {
namespace {

constexpr int kBrickEdge = FVP_BRICK_EDGE;
constexpr int kBrickCorners = (kBrickEdge + 1) * (kBrickEdge + 1) * (kBrickEdge + 1);

int localIndex(int x, int y, int z) {
  return x + kBrickEdge * (y + kBrickEdge * z);
}

std::array<int, 3> localCoords(int local) {
  return {local % kBrickEdge, (local / kBrickEdge) % kBrickEdge, local / (kBrickEdge * kBrickEdge)};
}

// Occupancy bits of one 8x8x8 brick and the Embree geometry of its exposed faces.
struct Brick {
  std::array<std::uint64_t, FVP_BRICK_VOXELS / 64> bits{};
  int count = 0;
  unsigned geom_id = RTC_INVALID_GEOMETRY_ID;
  bool test(int local) const { return (bits[local >> 6] >> (local & 63)) & 1u; }
};

// What a hit on geometry geomID means: the brick's first voxel and, per quad (primID),
// the local index of the occupied voxel the face belongs to.
struct GeometryInfo {
  std::array<int, 3> base{};
  std::vector<std::uint16_t> face_voxel;
};

}  // namespace

struct OccupiedVoxelScene::Impl {
  GridGeometry grid;
  accel::GridParams params{};
  std::array<int, 3> bricks_per_axis{};
  std::unordered_map<std::int64_t, Brick> bricks;  // only bricks with occupied voxels or geometry
  std::unordered_set<std::int64_t> dirty;
  std::vector<GeometryInfo> geometries;  // by Embree geomID
  std::size_t occupied_count = 0;
  std::size_t face_count = 0;
  std::size_t geometry_count = 0;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;

  explicit Impl(const GridGeometry& g) : grid(g), params(g.params()) {
    for (int a = 0; a < 3; ++a) {
      if (g.dims[a] <= 0 || g.dims[a] % kBrickEdge != 0) {
        throw std::invalid_argument(
            "OccupiedVoxelScene: grid dims must be positive multiples of 8");
      }
      bricks_per_axis[a] = g.dims[a] / kBrickEdge;
    }
    device = FVP_RTC(nullptr, rtcNewDevice(nullptr));
    try {
      FVP_RTC(device,
              rtcSetDeviceErrorFunction(device, accel::detail::embreeErrorCallback, nullptr));
      scene = FVP_RTC(device, rtcNewScene(device));
      // Dynamic: bricks change every scan; robust: rays through the shared edges of
      // neighbouring faces must not slip between them.
      FVP_RTC(device, rtcSetSceneFlags(scene, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST));
      FVP_RTC(device, rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_LOW));
      FVP_RTC(device, rtcCommitScene(scene));
    } catch (...) {
      release();
      throw;
    }
  }
  ~Impl() { release(); }

  void release() noexcept {
    // Releasing cannot usefully fail; errors here are not reported (destructor path).
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
    scene = nullptr;
    device = nullptr;
  }

  std::int64_t brickKey(const std::array<int, 3>& b) const {
    return b[0] +
           std::int64_t{bricks_per_axis[0]} * (b[1] + std::int64_t{bricks_per_axis[1]} * b[2]);
  }
  std::array<int, 3> brickOfKey(std::int64_t key) const {
    const std::int64_t nx = bricks_per_axis[0], ny = bricks_per_axis[1];
    return {static_cast<int>(key % nx), static_cast<int>((key / nx) % ny),
            static_cast<int>(key / (nx * ny))};
  }

  bool inGrid(const std::array<int, 3>& i) const {
    return i[0] >= 0 && i[1] >= 0 && i[2] >= 0 && i[0] < grid.dims[0] && i[1] < grid.dims[1] &&
           i[2] < grid.dims[2];
  }

  bool isOccupied(const std::array<int, 3>& i) const {
    const auto it = bricks.find(brickKey({i[0] >> 3, i[1] >> 3, i[2] >> 3}));
    return it != bricks.end() && it->second.test(localIndex(i[0] & 7, i[1] & 7, i[2] & 7));
  }

  void set(const std::array<int, 3>& i, bool occupied) {
    const std::array<int, 3> b{i[0] >> 3, i[1] >> 3, i[2] >> 3};
    const std::array<int, 3> l{i[0] & 7, i[1] & 7, i[2] & 7};
    const std::int64_t key = brickKey(b);
    const int local = localIndex(l[0], l[1], l[2]);
    if (!occupied) {
      const auto it = bricks.find(key);
      if (it == bricks.end() || !it->second.test(local)) return;
      it->second.bits[local >> 6] &= ~(std::uint64_t{1} << (local & 63));
      --it->second.count;
      --occupied_count;
    } else {
      Brick& brick = bricks[key];
      if (brick.test(local)) return;
      brick.bits[local >> 6] |= std::uint64_t{1} << (local & 63);
      ++brick.count;
      ++occupied_count;
    }
    dirty.insert(key);
    // A voxel on a brick face also exposes or hides a face of the neighbouring brick.
    for (int a = 0; a < 3; ++a) {
      for (int s : {-1, 1}) {
        if ((s < 0 && l[a] != 0) || (s > 0 && l[a] != kBrickEdge - 1)) continue;
        std::array<int, 3> nb = b;
        nb[a] += s;
        if (nb[a] < 0 || nb[a] >= bricks_per_axis[a]) continue;
        dirty.insert(brickKey(nb));
      }
    }
  }

  void detach(Brick& brick) {
    if (brick.geom_id == RTC_INVALID_GEOMETRY_ID) return;
    FVP_RTC(device, rtcDetachGeometry(scene, brick.geom_id));
    face_count -= geometries[brick.geom_id].face_voxel.size();
    geometries[brick.geom_id] = {};
    brick.geom_id = RTC_INVALID_GEOMETRY_ID;
    --geometry_count;
  }

  // Rebuilds one brick's quad mesh from the current occupancy.
  void rebuild(const std::array<int, 3>& b, Brick& brick) {
    detach(brick);
    if (brick.count == 0) return;
    const std::array<int, 3> base{b[0] * kBrickEdge, b[1] * kBrickEdge, b[2] * kBrickEdge};
    std::array<std::int16_t, kBrickCorners> corner_vertex;
    corner_vertex.fill(-1);
    std::vector<float> vertices;
    std::vector<std::uint32_t> indices;
    std::vector<std::uint16_t> face_voxel;
    auto vertexOf = [&](int cx, int cy, int cz) -> std::uint32_t {
      const int corner = cx + (kBrickEdge + 1) * (cy + (kBrickEdge + 1) * cz);
      if (corner_vertex[corner] < 0) {
        corner_vertex[corner] = static_cast<std::int16_t>(vertices.size() / 3);
        const double size = params.voxel_size_m;
        vertices.push_back(static_cast<float>(params.origin_x_m + double(base[0] + cx) * size));
        vertices.push_back(static_cast<float>(params.origin_y_m + double(base[1] + cy) * size));
        vertices.push_back(static_cast<float>(params.origin_z_m + double(base[2] + cz) * size));
      }
      return static_cast<std::uint32_t>(corner_vertex[corner]);
    };
    for (int w = 0; w < FVP_BRICK_VOXELS / 64; ++w) {
      for (std::uint64_t bits = brick.bits[w]; bits != 0; bits &= bits - 1) {
        const int local = w * 64 + std::countr_zero(bits);
        const std::array<int, 3> l = localCoords(local);
        for (int a = 0; a < 3; ++a) {
          for (int s : {0, 1}) {
            std::array<int, 3> n{base[0] + l[0], base[1] + l[1], base[2] + l[2]};
            n[a] += s == 0 ? -1 : 1;
            if (inGrid(n) && isOccupied(n)) continue;  // hidden face
            // The face lies in the plane l[a] + s; its corners run over the other two axes.
            const int u = (a + 1) % 3, v = (a + 2) % 3;
            std::array<int, 3> c = l;
            c[a] += s;
            std::array<std::uint32_t, 4> quad;
            const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
            for (int k = 0; k < 4; ++k) {
              std::array<int, 3> corner = c;
              corner[u] += du[k];
              corner[v] += dv[k];
              quad[k] = vertexOf(corner[0], corner[1], corner[2]);
            }
            indices.insert(indices.end(), quad.begin(), quad.end());
            face_voxel.push_back(static_cast<std::uint16_t>(local));
          }
        }
      }
    }
    if (face_voxel.empty()) return;  // fully enclosed by occupied neighbours
    RTCGeometry geometry = FVP_RTC(device, rtcNewGeometry(device, RTC_GEOMETRY_TYPE_QUAD));
    try {
      auto* vb = static_cast<float*>(FVP_RTC(
          device, rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                          3 * sizeof(float), vertices.size() / 3)));
      std::copy(vertices.begin(), vertices.end(), vb);
      auto* ib = static_cast<std::uint32_t*>(FVP_RTC(
          device, rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4,
                                          4 * sizeof(std::uint32_t), face_voxel.size())));
      std::copy(indices.begin(), indices.end(), ib);
      FVP_RTC(device, rtcCommitGeometry(geometry));
      brick.geom_id = FVP_RTC(device, rtcAttachGeometry(scene, geometry));
    } catch (...) {
      rtcReleaseGeometry(geometry);
      throw;
    }
    FVP_RTC(device, rtcReleaseGeometry(geometry));  // the scene holds its own reference
    if (geometries.size() <= brick.geom_id) geometries.resize(brick.geom_id + 1);
    face_count += face_voxel.size();
    geometries[brick.geom_id] = {base, std::move(face_voxel)};
    ++geometry_count;
  }

  std::size_t commit() {
    std::size_t rebuilt = 0;
    for (const std::int64_t key : dirty) {
      const auto it = bricks.find(key);
      if (it == bricks.end()) continue;
      rebuild(brickOfKey(key), it->second);
      ++rebuilt;
      if (it->second.count == 0) bricks.erase(it);
    }
    dirty.clear();
    FVP_RTC(device, rtcCommitScene(scene));
    return rebuilt;
  }

  VoxelHit makeHit(unsigned geom_id, unsigned prim_id, float t, const float* org,
                   const float* dir) const {
    const GeometryInfo& info = geometries.at(geom_id);
    const std::array<int, 3> l = localCoords(info.face_voxel.at(prim_id));
    VoxelHit hit;
    hit.voxel = {info.base[0] + l[0], info.base[1] + l[1], info.base[2] + l[2]};
    hit.t = t;
    hit.point_m = {org[0] + t * dir[0], org[1] + t * dir[1], org[2] + t * dir[2]};
    return hit;
  }
};

OccupiedVoxelScene::OccupiedVoxelScene(const GridGeometry& grid)
    : impl_(std::make_unique<Impl>(grid)) {}

OccupiedVoxelScene::OccupiedVoxelScene(const GridGeometry& grid,
                                       const std::vector<std::array<int, 3>>& occupied)
    : OccupiedVoxelScene(grid) {
  assignOccupied(occupied);
  commit();
}

OccupiedVoxelScene::~OccupiedVoxelScene() = default;
OccupiedVoxelScene::OccupiedVoxelScene(OccupiedVoxelScene&&) noexcept = default;
OccupiedVoxelScene& OccupiedVoxelScene::operator=(OccupiedVoxelScene&&) noexcept = default;

const GridGeometry& OccupiedVoxelScene::grid() const {
  return impl_->grid;
}

void OccupiedVoxelScene::setOccupied(const std::array<int, 3>& index, bool occupied) {
  if (!impl_->inGrid(index)) {
    throw std::out_of_range("OccupiedVoxelScene::setOccupied: voxel (" + std::to_string(index[0]) +
                            ", " + std::to_string(index[1]) + ", " + std::to_string(index[2]) +
                            ") is outside the grid");
  }
  impl_->set(index, occupied);
}

void OccupiedVoxelScene::setOccupiedUnchecked(const std::array<int, 3>& index, bool occupied) {
  impl_->set(index, occupied);
}

bool OccupiedVoxelScene::isOccupied(const std::array<int, 3>& index) const {
  return impl_->inGrid(index) && impl_->isOccupied(index);
}

void OccupiedVoxelScene::assignOccupied(const std::vector<std::array<int, 3>>& occupied) {
  for (auto& [key, brick] : impl_->bricks) {
    if (brick.count > 0) impl_->dirty.insert(key);
    impl_->occupied_count -= brick.count;
    brick.bits.fill(0);
    brick.count = 0;
  }
  for (const auto& index : occupied) setOccupied(index, true);
}

std::size_t OccupiedVoxelScene::commit() {
  return impl_->commit();
}
bool OccupiedVoxelScene::hasPendingChanges() const {
  return !impl_->dirty.empty();
}
std::size_t OccupiedVoxelScene::occupiedCount() const {
  return impl_->occupied_count;
}
std::size_t OccupiedVoxelScene::brickGeometryCount() const {
  return impl_->geometry_count;
}
std::size_t OccupiedVoxelScene::faceCount() const {
  return impl_->face_count;
}

std::optional<VoxelHit> OccupiedVoxelScene::firstHit(const Eigen::Vector3f& origin_m,
                                                     const Eigen::Vector3f& direction, float t_min,
                                                     float t_max) const {
  if (direction.squaredNorm() == 0.0f || !origin_m.allFinite() || !direction.allFinite()) {
    return std::nullopt;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = origin_m.x();
  rh.ray.org_y = origin_m.y();
  rh.ray.org_z = origin_m.z();
  rh.ray.dir_x = direction.x();
  rh.ray.dir_y = direction.y();
  rh.ray.dir_z = direction.z();
  rh.ray.tnear = t_min;
  rh.ray.tfar = t_max;
  rh.ray.mask = 0xffffffffu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  FVP_RTC(impl_->device, rtcIntersect1(impl_->scene, &context, &rh));
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  return impl_->makeHit(rh.hit.geomID, rh.hit.primID, rh.ray.tfar, origin_m.data(),
                        direction.data());
}

std::vector<std::optional<VoxelHit>> OccupiedVoxelScene::firstHits(
    const std::vector<accel::Ray>& segments) const {
  std::vector<std::optional<VoxelHit>> hits(segments.size());
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit16 packet;
  alignas(64) int valid[16];  // Embree requires packet-size alignment of the mask
  for (std::size_t first = 0; first < segments.size(); first += 16) {
    const std::size_t n = std::min<std::size_t>(16, segments.size() - first);
    for (std::size_t k = 0; k < 16; ++k) {
      valid[k] = 0;
      packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
      if (k >= n) continue;
      const accel::Ray& s = segments[first + k];
      const float dx = s.end_m[0] - s.origin_m[0], dy = s.end_m[1] - s.origin_m[1],
                  dz = s.end_m[2] - s.origin_m[2];
      packet.ray.org_x[k] = s.origin_m[0];
      packet.ray.org_y[k] = s.origin_m[1];
      packet.ray.org_z[k] = s.origin_m[2];
      packet.ray.dir_x[k] = dx;
      packet.ray.dir_y[k] = dy;
      packet.ray.dir_z[k] = dz;
      packet.ray.tnear[k] = 0.0f;
      packet.ray.tfar[k] = 1.0f;
      packet.ray.time[k] = 0.0f;
      packet.ray.mask[k] = 0xffffffffu;
      packet.ray.id[k] = static_cast<unsigned>(k);
      packet.ray.flags[k] = 0;
      const bool usable = std::isfinite(dx) && std::isfinite(dy) && std::isfinite(dz) &&
                          (dx != 0.0f || dy != 0.0f || dz != 0.0f);
      valid[k] = usable ? -1 : 0;
    }
    FVP_RTC(impl_->device, rtcIntersect16(valid, impl_->scene, &context, &packet));
    for (std::size_t k = 0; k < n; ++k) {
      if (valid[k] == 0 || packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
      const float org[3] = {packet.ray.org_x[k], packet.ray.org_y[k], packet.ray.org_z[k]};
      const float dir[3] = {packet.ray.dir_x[k], packet.ray.dir_y[k], packet.ray.dir_z[k]};
      hits[first + k] =
          impl_->makeHit(packet.hit.geomID[k], packet.hit.primID[k], packet.ray.tfar[k], org, dir);
    }
  }
  return hits;
}

bool OccupiedVoxelScene::occluded(const Eigen::Vector3f& origin_m,
                                  const Eigen::Vector3f& end_m) const {
  const Eigen::Vector3f d = end_m - origin_m;
  if (!origin_m.allFinite() || !d.allFinite() || d.squaredNorm() == 0.0f) return false;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = origin_m.x();
  ray.org_y = origin_m.y();
  ray.org_z = origin_m.z();
  ray.dir_x = d.x();
  ray.dir_y = d.y();
  ray.dir_z = d.z();
  ray.tnear = 0.0f;
  ray.tfar = 1.0f;
  ray.mask = 0xffffffffu;
  FVP_RTC(impl_->device, rtcOccluded1(impl_->scene, &context, &ray));
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

std::vector<std::uint8_t> OccupiedVoxelScene::occludedBatch(
    const std::vector<accel::Ray>& segments) const {
  std::vector<std::uint8_t> result(segments.size(), 0);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay16 packet;
  alignas(64) int valid[16];  // Embree requires packet-size alignment of the mask
  for (std::size_t first = 0; first < segments.size(); first += 16) {
    const std::size_t n = std::min<std::size_t>(16, segments.size() - first);
    for (std::size_t k = 0; k < 16; ++k) {
      valid[k] = 0;
      packet.tfar[k] = 1.0f;
      if (k >= n) continue;
      const accel::Ray& s = segments[first + k];
      const float dx = s.end_m[0] - s.origin_m[0], dy = s.end_m[1] - s.origin_m[1],
                  dz = s.end_m[2] - s.origin_m[2];
      packet.org_x[k] = s.origin_m[0];
      packet.org_y[k] = s.origin_m[1];
      packet.org_z[k] = s.origin_m[2];
      packet.dir_x[k] = dx;
      packet.dir_y[k] = dy;
      packet.dir_z[k] = dz;
      packet.tnear[k] = 0.0f;
      packet.time[k] = 0.0f;
      packet.mask[k] = 0xffffffffu;
      packet.id[k] = static_cast<unsigned>(k);
      packet.flags[k] = 0;
      const bool usable = std::isfinite(dx) && std::isfinite(dy) && std::isfinite(dz) &&
                          (dx != 0.0f || dy != 0.0f || dz != 0.0f);
      valid[k] = usable ? -1 : 0;
    }
    FVP_RTC(impl_->device, rtcOccluded16(valid, impl_->scene, &context, &packet));
    for (std::size_t k = 0; k < n; ++k) {
      result[first + k] = (valid[k] != 0 && packet.tfar[k] < 0.0f) ? 1 : 0;
    }
  }
  return result;
}

}  // namespace fvp::host::map
