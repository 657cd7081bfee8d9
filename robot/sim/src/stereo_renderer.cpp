#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/object_ids.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <numbers>
#include <random>
#include <stdexcept>

#include "fvp/accel/embree_check.h"
#include "fvp/robot/sim/tag_image.h"
#include "procedural_texture.h"
#include "scene_primitive.h"

namespace fvp::robot::sim {
namespace {

using detail::Primitive;
using detail::PrimitiveKind;

// Texture feature sizes: at 0.3 m one pixel spans 0.27 mm, so speckle of ~0.5 mm gives
// StereoSGBM's 3x3 blocks something to lock on to without aliasing at 4 samples per pixel.
constexpr double kFruitSpeckleM = 0.0005;
constexpr double kLeafNoiseM = 0.0006;
constexpr double kLeafVeinSpacingM = 0.007;
constexpr double kBarkNoiseM = 0.0012;
constexpr double kPaperNoiseM = 0.0008;
// Albedos (linear): leaves a mid green, bark a greyish brown (low saturation, see the
// palette note in world.cpp), the tag's print and paper.
const Eigen::Vector3d kLeafRgb(0.070, 0.260, 0.027);      // sRGB ~(0.30, 0.55, 0.18)
const Eigen::Vector3d kLeafVeinRgb(0.170, 0.340, 0.060);  // lighter, yellower green
const Eigen::Vector3d kBarkRgb(0.150, 0.095, 0.060);      // sRGB ~(0.42, 0.34, 0.27)
const Eigen::Vector3d kPlateBackRgb(0.25, 0.25, 0.25);
constexpr double kTagWhite = 0.85;
constexpr double kTagBlack = 0.04;
// Distinct seeds per texture family keep their noise patterns uncorrelated.
constexpr std::uint64_t kFruitSeed = 0x1f2e3d4cULL, kLeafSeed = 0x5b6a7988ULL,
                        kBarkSeed = 0x9cabbac9ULL, kPaperSeed = 0xd8e7f601ULL;
constexpr float kRayTNear = 1e-4f;  // ignore hits within 0.1 mm of the camera centre
// Shadow rays end this short of the shaded point (float hit positions are ~1e-7 m exact).
constexpr double kShadowRayGapM = 1e-5;
// The sun's shadow rays reach this far: past the whole tree.
constexpr double kSunRayM = 10.0;

double linearToSrgb(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

// Embree's intersect context, extended: the user-geometry callback reads the render's
// options from it (Embree hands back the pointer we passed).
struct SceneContext {
  RTCIntersectContext embree;
  bool with_leaves = true;
};

struct Hit {
  int primitive = -1;  ///< index into primitives, -1 for a miss
  double t = 0.0;      ///< ray parameter for the (unnormalised) direction passed in
};

// One shading sample. `region` names what the sample landed on (primitive, shadow, tag cell):
// a pixel whose four corners share a region has no silhouette, shadow or print edge in it.
struct ShadedSample {
  Eigen::Vector3d rgb = Eigen::Vector3d::Zero();
  std::uint32_t region = 0;  ///< 0: the ray hit nothing
};

// A pixel-corner sample kept for the second pass: float radiance is ample for 8-bit output.
struct CornerSample {
  Eigen::Vector3f rgb;
  std::uint32_t region;
};

/// One render's stereo rig: each camera's eye and rays, the flash, and the pixel sampling.
struct RenderRig {
  Eigen::Matrix3d R;
  host::StereoIntrinsics in;
  // The right camera's rows are offset: its pixel row v sees what row v - offset would.
  std::array<double, 2> row_offset_px;
  std::array<Eigen::Vector3d, 2> eyes;
  Eigen::Vector3d flash;  ///< one flash for both cameras' simultaneous exposure
  int spp = 1, strata_x = 1, strata_y = 1;

  Eigen::Vector3d rayDir(int camera, double u, double v) const {
    return Eigen::Vector3d(R * Eigen::Vector3d((u - in.cx_px) / in.fx_px,
                                               (v - row_offset_px[camera] - in.cy_px) / in.fy_px,
                                               1.0));
  }
};

// Noise differs per view: mix the seed with the pose's bits.
std::uint64_t viewSeed(std::uint64_t noise_seed, const Eigen::Isometry3d& T_world_camera) {
  std::uint64_t view_seed = detail::mix64(noise_seed);
  for (int i = 0; i < 16; ++i) {
    std::uint64_t bits = 0;
    const double value = T_world_camera.matrix().data()[i];
    std::memcpy(&bits, &value, sizeof(bits));
    view_seed = detail::hashCombine(view_seed, bits);
  }
  return view_seed;
}

// The mean of a pixel's four corners (c: its top-left one) when they all landed on one
// region; false otherwise.
bool uniformCorners(const CornerSample* c, int corner_cols, Eigen::Vector3d& linear) {
  const CornerSample& c00 = c[0];
  const CornerSample& c01 = c[1];
  const CornerSample& c10 = c[corner_cols];
  const CornerSample& c11 = c[corner_cols + 1];
  const bool uniform =
      c00.region == c01.region && c00.region == c10.region && c00.region == c11.region;
  if (uniform) linear = (0.25f * (c00.rgb + c01.rgb + c10.rgb + c11.rgb)).cast<double>();
  return uniform;
}

// A pixel's linear radiance as 8-bit sRGB, BGR, with the sensor's Gaussian noise.
void writePixel(cv::Vec3b& out, const Eigen::Vector3d& linear, std::uint64_t pixel_seed, int camera,
                double noise_sigma) {
  for (int channel = 0; channel < 3; ++channel) {
    double noise = 0.0;
    if (noise_sigma > 0.0) {
      // Box-Muller from two hashed uniforms.
      const std::uint64_t h = detail::hashCombine(pixel_seed, 0x100 + 4 * camera + channel);
      const double u1 = 1.0 - detail::unitFromHash(h);
      const double u2 = detail::unitFromHash(detail::mix64(h));
      noise = noise_sigma * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
    }
    const double value = 255.0 * linearToSrgb(linear[channel]) + noise;
    out[2 - channel] = static_cast<std::uint8_t>(std::clamp(std::lround(value), 0L, 255L));
  }
}

// Exceptions must not leave an OpenMP region: keep the first, rethrow after the loop.
class FirstError {
 public:
  void keep() {
#pragma omp critical(fvp_render_error)
    if (!error_) error_ = std::current_exception();
  }
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::exception_ptr error_;
};

}  // namespace

struct StereoRenderer::Impl {
  World world;
  RenderConfig config;
  std::vector<Primitive> primitives;
  /// CV_8U tag image (total_width^2 cells) of each cluster's tag; empty without a tag.
  std::vector<cv::Mat> tag_cells;
  double tag_cell_m = 0.0;  ///< edge of one tag cell (every tag has the same size)
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  mutable std::atomic<double> last_seconds{0.0};

  Impl(const World& w, const RenderConfig& c) : world(w), config(c) {}
  ~Impl() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }

  void build();
  static void boundsCallback(const RTCBoundsFunctionArguments* args);
  static void intersectCallback(const RTCIntersectFunctionNArguments* args);
  static void occludedCallback(const RTCOccludedFunctionNArguments* args);

  Hit trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, bool with_leaves) const;
  /// Albedo at a surface point; `subregion` gets the tag cell (print edges are edges too).
  Eigen::Vector3d albedo(const Primitive& prim, const detail::SurfacePoint& surface,
                         const Eigen::Vector3d& dir, std::uint32_t& subregion) const;
  /// Whether nothing lies between p and the light at `light` (a point) or, with
  /// `directional`, along the direction `light` for kSunRayM.
  bool lit(const Eigen::Vector3d& p, const Eigen::Vector3d& light, bool with_leaves,
           bool directional = false) const;
  ShadedSample radiance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                        const Eigen::Vector3d& flash, bool with_leaves) const;
  int threadCount() const { return config.threads > 0 ? config.threads : omp_get_max_threads(); }
  RenderRig rig(const Eigen::Isometry3d& T_world_camera) const;
  /// Adaptive anti-aliasing's first pass: every pixel corner of both cameras shaded once.
  void shadeCorners(const RenderRig& r, bool with_leaves, int width, int height,
                    std::array<std::vector<CornerSample>, 2>& corners) const;
  /// A pixel's radiance from r.spp stratified, jittered samples.
  Eigen::Vector3d sampledRadiance(const RenderRig& r, int camera, int row, int col,
                                  std::uint64_t pixel_seed, bool with_leaves) const;
  /// The pair (unless options.images is false) and, when truth is set, the exact layers.
  host::StereoFrame render(const Eigen::Isometry3d& T_world_camera, const RenderOptions& options,
                           GroundTruthImages* truth) const;
};

void StereoRenderer::Impl::build() {
  for (const Fruitlet& f : world.fruitlets()) {
    primitives.push_back(detail::makeEllipsoid(f, kFirstFruitletId + f.index));
  }
  for (std::size_t i = 0; i < world.branches().size(); ++i) {
    primitives.push_back(detail::makeCapsule(world.branches()[i], static_cast<int>(i), kTreeId));
  }
  for (const Leaf& leaf : world.leaves()) {
    primitives.push_back(detail::makeLeaf(leaf, kFirstLeafId + leaf.index));
  }
  if (world.hasTag()) {
    for (const FruitletCluster& cluster : world.clusters()) {
      primitives.push_back(detail::makePlate(cluster.tag, kTagId));
      primitives.back().source_index = static_cast<int>(tag_cells.size());
      tag_cells.push_back(tag36h11Image(cluster.tag.tag_id));
    }
    tag_cell_m = world.tag().tag_size_m / tag36h11WidthAtBorder();
  }

  device = FVP_RTC(nullptr, rtcNewDevice(nullptr));
  FVP_RTC(device, rtcSetDeviceErrorFunction(device, accel::detail::embreeErrorCallback, nullptr));
  scene = FVP_RTC(device, rtcNewScene(device));
  FVP_RTC(device, rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH));
  if (!primitives.empty()) {
    RTCGeometry geometry = FVP_RTC(device, rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER));
    FVP_RTC(device, rtcSetGeometryUserPrimitiveCount(geometry,
                                                     static_cast<unsigned int>(primitives.size())));
    FVP_RTC(device, rtcSetGeometryUserData(geometry, this));
    FVP_RTC(device, rtcSetGeometryBoundsFunction(geometry, &Impl::boundsCallback, nullptr));
    FVP_RTC(device, rtcSetGeometryIntersectFunction(geometry, &Impl::intersectCallback));
    FVP_RTC(device, rtcSetGeometryOccludedFunction(geometry, &Impl::occludedCallback));
    FVP_RTC(device, rtcCommitGeometry(geometry));
    FVP_RTC(device, rtcAttachGeometry(scene, geometry));
    FVP_RTC(device, rtcReleaseGeometry(geometry));
  }
  FVP_RTC(device, rtcCommitScene(scene));
}

void StereoRenderer::Impl::boundsCallback(const RTCBoundsFunctionArguments* args) {
  const auto* self = static_cast<const Impl*>(args->geometryUserPtr);
  const auto box = detail::bounds(self->primitives[args->primID]);
  RTCBounds* out = args->bounds_o;
  out->lower_x = static_cast<float>(box[0].x());
  out->lower_y = static_cast<float>(box[0].y());
  out->lower_z = static_cast<float>(box[0].z());
  out->upper_x = static_cast<float>(box[1].x());
  out->upper_y = static_cast<float>(box[1].y());
  out->upper_z = static_cast<float>(box[1].z());
}

void StereoRenderer::Impl::intersectCallback(const RTCIntersectFunctionNArguments* args) {
  const auto* self = static_cast<const Impl*>(args->geometryUserPtr);
  const Primitive& prim = self->primitives[args->primID];
  const auto* context = reinterpret_cast<const SceneContext*>(args->context);
  if (prim.kind == PrimitiveKind::kLeaf && !context->with_leaves) return;
  RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned int i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const Eigen::Vector3d origin(RTCRayN_org_x(rays, args->N, i), RTCRayN_org_y(rays, args->N, i),
                                 RTCRayN_org_z(rays, args->N, i));
    const Eigen::Vector3d dir(RTCRayN_dir_x(rays, args->N, i), RTCRayN_dir_y(rays, args->N, i),
                              RTCRayN_dir_z(rays, args->N, i));
    const double scale = dir.norm();
    float& tfar = RTCRayN_tfar(rays, args->N, i);
    // Intersect with the unit direction in double; t along dir is t_unit / |dir|.
    const double t_unit =
        detail::intersect(prim, origin, dir / scale, RTCRayN_tnear(rays, args->N, i) * scale,
                          static_cast<double>(tfar) * scale);
    if (t_unit < 0.0) continue;
    tfar = static_cast<float>(t_unit / scale);
    RTCHitN_geomID(hits, args->N, i) = args->geomID;
    RTCHitN_primID(hits, args->N, i) = args->primID;
    RTCHitN_instID(hits, args->N, i, 0) = args->context->instID[0];
    RTCHitN_u(hits, args->N, i) = 0.0f;
    RTCHitN_v(hits, args->N, i) = 0.0f;
    // Ng is unused: shading recomputes the exact normal from the primitive.
    RTCHitN_Ng_x(hits, args->N, i) = 0.0f;
    RTCHitN_Ng_y(hits, args->N, i) = 0.0f;
    RTCHitN_Ng_z(hits, args->N, i) = 1.0f;
  }
}

void StereoRenderer::Impl::occludedCallback(const RTCOccludedFunctionNArguments* args) {
  const auto* self = static_cast<const Impl*>(args->geometryUserPtr);
  const Primitive& prim = self->primitives[args->primID];
  const auto* context = reinterpret_cast<const SceneContext*>(args->context);
  if (prim.kind == PrimitiveKind::kLeaf && !context->with_leaves) return;
  for (unsigned int i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const Eigen::Vector3d origin(RTCRayN_org_x(args->ray, args->N, i),
                                 RTCRayN_org_y(args->ray, args->N, i),
                                 RTCRayN_org_z(args->ray, args->N, i));
    const Eigen::Vector3d dir(RTCRayN_dir_x(args->ray, args->N, i),
                              RTCRayN_dir_y(args->ray, args->N, i),
                              RTCRayN_dir_z(args->ray, args->N, i));
    const double scale = dir.norm();
    float& tfar = RTCRayN_tfar(args->ray, args->N, i);
    if (detail::intersect(prim, origin, dir / scale, RTCRayN_tnear(args->ray, args->N, i) * scale,
                          static_cast<double>(tfar) * scale) >= 0.0) {
      tfar = -std::numeric_limits<float>::infinity();  // Embree's "occluded" mark
    }
  }
}

Hit StereoRenderer::Impl::trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                bool with_leaves) const {
  SceneContext context;
  rtcInitIntersectContext(&context.embree);
  context.with_leaves = with_leaves;
  RTCRayHit rayhit;
  std::memset(&rayhit, 0, sizeof(rayhit));
  rayhit.ray.org_x = static_cast<float>(origin.x());
  rayhit.ray.org_y = static_cast<float>(origin.y());
  rayhit.ray.org_z = static_cast<float>(origin.z());
  rayhit.ray.dir_x = static_cast<float>(dir.x());
  rayhit.ray.dir_y = static_cast<float>(dir.y());
  rayhit.ray.dir_z = static_cast<float>(dir.z());
  rayhit.ray.tnear = kRayTNear;
  rayhit.ray.tfar = std::numeric_limits<float>::infinity();
  rayhit.ray.mask = 0xFFFFFFFFu;
  rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &context.embree, &rayhit);
  if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
  return {static_cast<int>(rayhit.hit.primID), static_cast<double>(rayhit.ray.tfar)};
}

Eigen::Vector3d StereoRenderer::Impl::albedo(const Primitive& prim,
                                             const detail::SurfacePoint& surface,
                                             const Eigen::Vector3d& dir,
                                             std::uint32_t& subregion) const {
  subregion = 0;
  const Eigen::Vector3d& p = surface.p_local;
  switch (prim.kind) {
    case PrimitiveKind::kEllipsoid: {
      // Speckle in value only: hue and saturation stay the palette's.
      // By identity: a fruitlet keeps its speckle when a neighbour falls off (A season).
      const std::uint64_t seed =
          detail::hashCombine(kFruitSeed, world.fruitlets()[prim.source_index].identity);
      const double fine = detail::fractalNoise(p / kFruitSpeckleM, seed, 2);
      const double coarse = detail::valueNoise(p / (4.0 * kFruitSpeckleM), seed + 1);
      const double value = 0.6 + 0.45 * (0.65 * fine + 0.35 * coarse);
      return value * world.fruitlets()[prim.source_index].rgb;
    }
    case PrimitiveKind::kLeaf: {
      const std::uint64_t seed = detail::hashCombine(kLeafSeed, prim.source_index);
      // Midrib along x and lateral veins slanting towards the tip.
      const double midrib = std::exp(-std::pow(p.y() / 0.0005, 2));
      const double phase = (p.x() - 1.2 * std::abs(p.y())) / kLeafVeinSpacingM;
      const double lateral = std::exp(-std::pow((phase - std::round(phase)) / 0.07, 2)) *
                             std::clamp(std::abs(p.y()) / 0.002, 0.0, 1.0);
      const double vein = std::clamp(std::max(midrib, 0.7 * lateral), 0.0, 1.0);
      const double noise = detail::fractalNoise(p / kLeafNoiseM, seed, 3);
      const double tint = 0.85 + 0.3 * detail::unitFromHash(seed);  // leaf-to-leaf variation
      const Eigen::Vector3d base = (1.0 - vein) * kLeafRgb + vein * kLeafVeinRgb;
      return tint * (0.55 + 0.9 * noise) * base;
    }
    case PrimitiveKind::kCapsule: {
      // Stretched along the branch like bark fissures: noise coordinates in a frame whose
      // first axis follows the branch.
      const Eigen::Vector3d axis = (prim.b_m - prim.a_m).normalized();
      const Eigen::Vector3d u = axis.unitOrthogonal();
      const Eigen::Vector3d w = axis.cross(u);
      const Eigen::Vector3d rel = p - prim.a_m;  // capsules' local frame is the world frame
      const Eigen::Vector3d q(rel.dot(axis) / (3.0 * kBarkNoiseM), rel.dot(u) / kBarkNoiseM,
                              rel.dot(w) / kBarkNoiseM);
      const double noise =
          detail::fractalNoise(q, detail::hashCombine(kBarkSeed, prim.source_index), 4);
      return (0.35 + 1.3 * noise) * kBarkRgb;
    }
    case PrimitiveKind::kPlate: {
      const double paper = 0.94 + 0.12 * detail::valueNoise(p / kPaperNoiseM, kPaperSeed);
      // The printed face looks along +z of the tag frame (into the plate).
      const double facing = prim.T_local_world.linear().row(2).dot(dir);
      if (facing <= 0.0) return paper * kPlateBackRgb;
      const cv::Mat& tag = tag_cells[static_cast<std::size_t>(prim.source_index)];
      const int cells = tag.cols;
      const int col = static_cast<int>(std::floor(p.x() / tag_cell_m + 0.5 * cells));
      const int row = static_cast<int>(std::floor(p.y() / tag_cell_m + 0.5 * cells));
      const bool white =
          col < 0 || row < 0 || col >= cells || row >= cells || tag.at<std::uint8_t>(row, col) != 0;
      subregion = white ? 1u : 2u;
      return Eigen::Vector3d::Constant(paper * (white ? kTagWhite : kTagBlack));
    }
  }
  return Eigen::Vector3d::Zero();
}

bool StereoRenderer::Impl::lit(const Eigen::Vector3d& p, const Eigen::Vector3d& light,
                               bool with_leaves, bool directional) const {
  SceneContext context;
  rtcInitIntersectContext(&context.embree);
  context.with_leaves = with_leaves;
  const Eigen::Vector3d flash = directional ? Eigen::Vector3d(p + kSunRayM * light) : light;
  const Eigen::Vector3d to_point = p - flash;
  RTCRay ray;
  std::memset(&ray, 0, sizeof(ray));
  ray.org_x = static_cast<float>(flash.x());
  ray.org_y = static_cast<float>(flash.y());
  ray.org_z = static_cast<float>(flash.z());
  ray.dir_x = static_cast<float>(to_point.x());
  ray.dir_y = static_cast<float>(to_point.y());
  ray.dir_z = static_cast<float>(to_point.z());
  ray.tnear = 0.0f;
  // Stop short of the shaded surface itself.
  ray.tfar = static_cast<float>(1.0 - kShadowRayGapM / to_point.norm());
  ray.mask = 0xFFFFFFFFu;
  rtcOccluded1(scene, &context.embree, &ray);
  return ray.tfar >= 0.0f;
}

ShadedSample StereoRenderer::Impl::radiance(const Eigen::Vector3d& origin,
                                            const Eigen::Vector3d& dir,
                                            const Eigen::Vector3d& flash, bool with_leaves) const {
  const Hit hit = trace(origin, dir, with_leaves);
  // Nothing hit: the night sky, or the daylit sky (region 0 either way).
  if (hit.primitive < 0) return {Eigen::Vector3d::Constant(config.sky_irradiance), 0u};
  const Primitive& prim = primitives[hit.primitive];
  const Eigen::Vector3d p = origin + hit.t * dir;
  // Regions: 8 per primitive: in or out of the flash's shadow (the tag's two print colours
  // when lit), times in or out of the sun's.
  const bool in_sun = config.sun_irradiance > 0.0 &&
                      lit(p, config.sun_direction_world, with_leaves, /*directional=*/true);
  const std::uint32_t base =
      1u + 8u * static_cast<std::uint32_t>(hit.primitive) + (in_sun ? 4u : 0u);
  const bool in_flash = lit(p, flash, with_leaves);
  // No light reaches it: black, without shading a surface (the flash's shadows cost what
  // they did before daylight existed).
  if (!in_flash && !in_sun && !(config.sky_irradiance > 0.0))
    return {Eigen::Vector3d::Zero(), base};
  const detail::SurfacePoint surface = detail::surfaceAt(prim, p);
  // Daylight: the sky's diffuse light everywhere, the sun's where it reaches (Lambert).
  double daylight = config.sky_irradiance;
  if (in_sun)
    daylight +=
        config.sun_irradiance * std::abs(surface.normal_world.dot(config.sun_direction_world));
  std::uint32_t subregion = 0;
  const Eigen::Vector3d reflectance = albedo(prim, surface, dir, subregion);
  if (!in_flash) return {daylight * reflectance, base};
  // Lambert's cosine and the flash's inverse-square falloff.
  const Eigen::Vector3d to_light = flash - p;
  const double distance2 = to_light.squaredNorm();
  const double cosine = std::abs(surface.normal_world.dot(to_light)) / std::sqrt(distance2);
  const double irradiance =
      config.flash_power * kFlashFullScaleDistanceM * kFlashFullScaleDistanceM / distance2;
  return {(cosine * irradiance + daylight) * reflectance, base + 1u + subregion};
}

StereoRenderer::StereoRenderer(const World& world, const RenderConfig& config)
    : impl_(std::make_unique<Impl>(world, config)) {
  const host::StereoIntrinsics& in = config.intrinsics;
  if (in.width_px <= 0 || in.height_px <= 0 || !(in.fx_px > 0.0) || !(in.fy_px > 0.0)) {
    throw std::invalid_argument("StereoRenderer: intrinsics need positive size and focal length");
  }
  if (!(in.baseline_m > 0.0) || !(in.cx_px >= 0.0 && in.cx_px <= in.width_px) ||
      !(in.cy_px >= 0.0 && in.cy_px <= in.height_px)) {
    throw std::invalid_argument(
        "StereoRenderer: intrinsics need baseline_m > 0 (the right camera is at +x) and the "
        "principal point inside the image");
  }
  if (config.samples_per_pixel < 1 || config.threads < 0) {
    throw std::invalid_argument("StereoRenderer: samples_per_pixel must be >= 1, threads >= 0");
  }
  if (!(config.noise_sigma >= 0.0) || !(config.flash_power >= 0.0)) {
    throw std::invalid_argument("StereoRenderer: noise_sigma and flash_power must be >= 0");
  }
  if (!(config.right_baseline_scale > 0.5 && config.right_baseline_scale < 2.0) ||
      !(std::abs(config.right_vertical_offset_px) <= 10.0)) {
    throw std::invalid_argument(
        "StereoRenderer: right_baseline_scale must be in (0.5, 2) and right_vertical_offset_px "
        "within +-10 px");
  }
  impl_->build();
}

StereoRenderer::~StereoRenderer() = default;

RenderConfig renderConfigFor(const WorldConfig& world, RenderConfig base, std::uint64_t seed) {
  base.right_baseline_scale = 1.0 + world.stereo_baseline_error;
  base.right_vertical_offset_px = world.stereo_vertical_misalignment_px;
  if (world.sun_strength > 0.0) {
    // "sun" in ASCII: a stream apart from the generator's and the other errors'.
    std::seed_seq seq{seed, std::uint64_t{0x73756e}};
    std::mt19937_64 rng(seq);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double elevation = (20.0 + 50.0 * unit(rng)) * std::numbers::pi / 180.0;
    const double azimuth = 2.0 * std::numbers::pi * unit(rng);
    base.sun_direction_world =
        Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                        std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    base.sun_irradiance = world.sun_strength;
    base.sky_irradiance = kSkyToSunRatio * world.sun_strength;
  }
  return base;
}

double StereoRenderer::lastRenderSeconds() const {
  return impl_->last_seconds.load();
}

const RenderConfig& StereoRenderer::config() const {
  return impl_->config;
}

host::StereoFrame StereoRenderer::render(const Eigen::Isometry3d& T_world_camera,
                                         const RenderOptions& options) const {
  if (!options.exact_disparity) return impl_->render(T_world_camera, options, nullptr);
  return renderWithGroundTruth(T_world_camera, options).frame;
}

RenderedView StereoRenderer::renderWithGroundTruth(const Eigen::Isometry3d& T_world_camera,
                                                   const RenderOptions& options) const {
  RenderedView view;
  view.frame = impl_->render(T_world_camera, options, &view.ground_truth);
  if (options.exact_disparity) {
    const host::StereoIntrinsics& K = view.frame.intrinsics;
    const cv::Mat& depth = view.ground_truth.depth_m;
    view.frame.disparity_px = cv::Mat::zeros(depth.size(), CV_32F);
    for (int v = 0; v < depth.rows; ++v)
      for (int u = 0; u < depth.cols; ++u)
        if (const float z = depth.at<float>(v, u); z > 0.0f)
          // What an ideal matcher measures on the rig as built (its true baseline).
          view.frame.disparity_px.at<float>(v, u) =
              static_cast<float>(K.disparityFromDepth(z) * impl_->config.right_baseline_scale);
  }
  return view;
}

RenderRig StereoRenderer::Impl::rig(const Eigen::Isometry3d& T_world_camera) const {
  RenderRig r;
  r.in = config.intrinsics;
  r.R = T_world_camera.linear();
  const double baseline_m = r.in.baseline_m * config.right_baseline_scale;  // the true one
  r.eyes = {T_world_camera.translation(), T_world_camera.translation() + baseline_m * r.R.col(0)};
  // One flash for the simultaneous exposure of both cameras, at the rig's centre.
  r.flash = T_world_camera.translation() + 0.5 * baseline_m * r.R.col(0);
  r.row_offset_px = {0.0, config.right_vertical_offset_px};
  r.spp = config.samples_per_pixel;
  r.strata_x = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(r.spp))));
  r.strata_y = (r.spp + r.strata_x - 1) / r.strata_x;
  return r;
}

void StereoRenderer::Impl::shadeCorners(const RenderRig& r, bool with_leaves, int width, int height,
                                        std::array<std::vector<CornerSample>, 2>& corners) const {
  const int corner_cols = width + 1;
  FirstError error;
  for (auto& grid : corners) grid.resize(static_cast<std::size_t>(corner_cols) * (height + 1));
#pragma omp parallel for schedule(dynamic, 2) num_threads(threadCount())
  for (int row = 0; row <= height; ++row) {
    try {
      for (int col = 0; col < corner_cols; ++col) {
        for (int camera = 0; camera < 2; ++camera) {
          const ShadedSample sample = radiance(
              r.eyes[camera], r.rayDir(camera, col - 0.5, row - 0.5), r.flash, with_leaves);
          corners[camera][static_cast<std::size_t>(row) * corner_cols + col] = {
              sample.rgb.cast<float>(), sample.region};
        }
      }
      // Embree's error state is per thread, so each row checks its own.
      accel::detail::checkEmbree(device, "rtcIntersect1", __FILE__, __LINE__);
    } catch (...) {
      error.keep();
    }
  }
  error.rethrow();
}

Eigen::Vector3d StereoRenderer::Impl::sampledRadiance(const RenderRig& r, int camera, int row,
                                                      int col, std::uint64_t pixel_seed,
                                                      bool with_leaves) const {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();
  for (int s = 0; s < r.spp; ++s) {
    double du = 0.0, dv = 0.0;  // one sample: the pixel centre
    if (r.spp > 1) {
      const std::uint64_t h = detail::hashCombine(pixel_seed, 2 * s + camera);
      const double jx = detail::unitFromHash(h);
      const double jy = detail::unitFromHash(detail::mix64(h));
      du = ((s % r.strata_x) + jx) / r.strata_x - 0.5;
      dv = ((s / r.strata_x) + jy) / r.strata_y - 0.5;
    }
    linear +=
        radiance(r.eyes[camera], r.rayDir(camera, col + du, row + dv), r.flash, with_leaves).rgb;
  }
  linear /= r.spp;
  return linear;
}

host::StereoFrame StereoRenderer::Impl::render(const Eigen::Isometry3d& T_world_camera,
                                               const RenderOptions& options,
                                               GroundTruthImages* truth) const {
  const auto start = std::chrono::steady_clock::now();
  const Impl& im = *this;
  const host::StereoIntrinsics& in = im.config.intrinsics;
  host::StereoFrame frame;
  frame.intrinsics = in;
  frame.T_world_camera = T_world_camera;
  const int width = in.width_px, height = in.height_px;
  if (options.images) {
    frame.left_bgr.create(height, width, CV_8UC3);
    frame.right_bgr.create(height, width, CV_8UC3);
  }
  if (truth) {
    truth->depth_m = cv::Mat::zeros(height, width, CV_32F);
    truth->object_id = cv::Mat::zeros(height, width, CV_32S);
  }
  const RenderRig r = rig(T_world_camera);
  const std::uint64_t view_seed = viewSeed(im.config.noise_seed, T_world_camera);

  // Adaptive anti-aliasing: shade every pixel corner once (shared by four pixels); a pixel
  // whose corners all land on one region (no silhouette, shadow or print edge inside) is the
  // mean of its corners, the others get `spp` stratified samples. Same filtering of texture
  // as 4 samples, at about a third of the rays of supersampling every pixel.
  const bool adaptive = options.images && r.spp > 1 && im.config.adaptive_antialiasing;
  const int corner_cols = width + 1;
  std::array<std::vector<CornerSample>, 2> corners;
  if (adaptive) shadeCorners(r, options.with_leaves, width, height, corners);

  FirstError error;
#pragma omp parallel for schedule(dynamic, 2) num_threads(im.threadCount())
  for (int row = 0; row < height; ++row) {
    try {
      for (int col = 0; col < width; ++col) {
        const std::uint64_t pixel_seed =
            detail::hashCombine(view_seed, static_cast<std::uint64_t>(row) * width + col);
        if (truth) {
          const Hit hit = im.trace(r.eyes[0], r.rayDir(0, col, row), options.with_leaves);
          if (hit.primitive >= 0) {
            // The direction has unit z in the camera frame, so t is the z-depth.
            truth->depth_m.at<float>(row, col) = static_cast<float>(hit.t);
            truth->object_id.at<std::int32_t>(row, col) = im.primitives[hit.primitive].object_id;
          }
        }
        if (!options.images) continue;
        for (int camera = 0; camera < 2; ++camera) {
          Eigen::Vector3d linear = Eigen::Vector3d::Zero();
          const bool uniform =
              adaptive && uniformCorners(corners[camera].data() +
                                             static_cast<std::size_t>(row) * corner_cols + col,
                                         corner_cols, linear);
          if (!uniform)
            linear = sampledRadiance(r, camera, row, col, pixel_seed, options.with_leaves);
          writePixel((camera == 0 ? frame.left_bgr : frame.right_bgr).at<cv::Vec3b>(row, col),
                     linear, pixel_seed, camera, im.config.noise_sigma);
        }
      }
      accel::detail::checkEmbree(im.device, "rtcIntersect1", __FILE__, __LINE__);
    } catch (...) {
      error.keep();
    }
  }
  error.rethrow();
  last_seconds.store(
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return frame;
}

}  // namespace fvp::robot::sim
