#include "fvp/host/report/viewer_scene.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fvp::host::report {

namespace {

/// "C<c>.<kind><index>", or "<kind><index>" outside a tree. Appended, not "C" + to_string(...):
/// GCC 12 warns falsely (-Wrestrict) on the latter.
std::string label(const char* kind, std::size_t index, std::optional<int> cluster) {
  std::string text;
  if (cluster) text.append("C").append(std::to_string(*cluster)).append(".");
  return text.append(kind).append(std::to_string(index));
}

}  // namespace

std::string detectionLabel(bool kept, std::size_t index, std::optional<int> cluster) {
  return label(kept ? "D" : "X", index, cluster);
}

std::string fruitletLabel(std::size_t index, std::optional<int> cluster) {
  return label("F", index, cluster);
}

nlohmann::json vec3Json(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

nlohmann::json poseJson(const Eigen::Isometry3d& T_world_frame) {
  const Eigen::Quaterniond q(T_world_frame.rotation());
  return {{"position_m", vec3Json(T_world_frame.translation())},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

std::string base64(const void* data, std::size_t bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* in = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes; i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes - i);
    const std::uint32_t word = (std::uint32_t{in[i]} << 16) |
                               (n > 1 ? std::uint32_t{in[i + 1]} << 8 : 0u) |
                               (n > 2 ? std::uint32_t{in[i + 2]} : 0u);
    for (std::size_t k = 0; k < 4; ++k)
      out.push_back(k <= n ? kAlphabet[(word >> (18 - 6 * k)) & 63u] : '=');
  }
  return out;
}

namespace {

template <typename T>
std::string base64Of(const std::vector<T>& values) {
  static_assert(std::is_arithmetic_v<T>);
  // The scene's binary arrays are little-endian: the bytes as they lie in memory.
  static_assert(std::endian::native == std::endian::little);
  return base64(values.data(), values.size() * sizeof(T));
}

void setCluster(nlohmann::json& j, std::optional<int> cluster) {
  if (cluster) j["cluster"] = *cluster;
}

}  // namespace

ViewerScene::ViewerScene(std::string title, std::string subtitle)
    : title_(std::move(title)), subtitle_(std::move(subtitle)) {}

void ViewerScene::setIntrinsics(const StereoIntrinsics& intrinsics) {
  intrinsics_ = intrinsics;
}

void ViewerScene::addFineVoxels(const map::MapEngine& map) {
  const map::GridGeometry& grid = map.gridGeometry(map::MapLevel::kFine);
  if (voxel_size_m_ > 0.0 && std::abs(grid.voxel_size_m - voxel_size_m_) > 1e-12)
    throw std::invalid_argument("ViewerScene::addFineVoxels: fine maps of different voxel sizes");
  voxel_size_m_ = grid.voxel_size_m;
  for (const auto& index : map.occupiedVoxels(map::MapLevel::kFine)) {
    voxels_.push_back({grid.first_voxel[0] + index[0], grid.first_voxel[1] + index[1],
                       grid.first_voxel[2] + index[2]});
    voxel_roi_.push_back(map.fineState(grid.voxelCenter_m(index)).roi ? 1 : 0);
  }
}

void ViewerScene::addMesh(const tsdf::TriangleMesh& mesh) {
  const auto first = static_cast<std::uint32_t>(mesh_vertices_m_.size() / 3);
  for (const auto& v : mesh.vertices_m)
    mesh_vertices_m_.insert(mesh_vertices_m_.end(), {v.x(), v.y(), v.z()});
  for (const auto& t : mesh.triangles)
    mesh_triangles_.insert(mesh_triangles_.end(), {first + t[0], first + t[1], first + t[2]});
}

void ViewerScene::addClusterRegion(const ClusterRegion& region, std::optional<int> cluster) {
  nlohmann::json j = {{"center_m", vec3Json(region.center_m())}, {"radius_m", region.radius_m()}};
  setCluster(j, cluster);
  regions_.push_back(std::move(j));
}

void ViewerScene::addTag(const Eigen::Isometry3d& T_world_tag, double size_m, int tag_id,
                         std::optional<int> cluster) {
  nlohmann::json j = poseJson(T_world_tag);
  j["id"] = tag_id;
  j["size_m"] = size_m;
  setCluster(j, cluster);
  tags_.push_back(std::move(j));
}

void ViewerScene::addCamera(int view, const Eigen::Isometry3d& T_world_camera,
                            nlohmann::json extra) {
  if (!extra.is_object()) extra = nlohmann::json::object();
  extra["view"] = view;
  extra.update(poseJson(T_world_camera));
  cameras_.push_back(std::move(extra));
}

void ViewerScene::addChosenCandidate(int iteration, const Eigen::Isometry3d& T_world_camera,
                                     double utility, bool reached, std::optional<int> cluster) {
  nlohmann::json j = poseJson(T_world_camera);
  j["iteration"] = iteration;
  j["utility"] = utility;
  j["reached"] = reached;
  setCluster(j, cluster);
  candidates_.push_back(std::move(j));
}

void ViewerScene::addSizing(const nlohmann::json& sizing, int view_offset,
                            std::optional<int> cluster) {
  // Ground truth first: a kept detection's match is the fruitlet that names it.
  const int first_detection = static_cast<int>(detections_.size());
  const int first_truth = static_cast<int>(truth_.size());
  std::vector<std::optional<int>> truth_of_kept;
  if (sizing.contains("sized_fruitlets")) truth_of_kept.resize(sizing["sized_fruitlets"].size());
  const bool scored = sizing.contains("fruitlets") && sizing["fruitlets"].is_array();
  if (scored) {
    int g = 0;
    for (const auto& f : sizing["fruitlets"]) {
      nlohmann::json t = {{"index", first_truth + g},
                          {"label", fruitletLabel(static_cast<std::size_t>(g), cluster)},
                          {"center_m", f.at("gt_center_m")},
                          {"size_mm", f.at("gt_size_mm")},
                          {"detection", nullptr}};
      setCluster(t, cluster);
      if (f.value("matched", false) && f.contains("detection")) {
        const int d = f["detection"].get<int>();
        if (d >= 0 && d < static_cast<int>(truth_of_kept.size())) {
          truth_of_kept[d] = first_truth + g;
          t["detection"] = first_detection + d;
        }
      }
      truth_.push_back(std::move(t));
      ++g;
    }
  }
  const auto add = [&](const nlohmann::json& d, bool kept, std::size_t index_in_list,
                       std::optional<int> truth) {
    const int id = static_cast<int>(detections_.size());
    nlohmann::json per_view = nlohmann::json::array();
    for (const auto& s : d.at("per_image"))
      per_view.push_back({{"view", s.at("view").get<int>() + view_offset},
                          {"size_mm", s.at("size_ours_mm")},
                          {"size_paper_mm", s.at("size_paper_mm")},
                          {"well_seen", s.value("well_seen", false)}});
    const nlohmann::json& support = d.at("support");
    nlohmann::json j = {{"id", id},
                        {"label", detectionLabel(kept, index_in_list, cluster)},
                        {"kept", kept},
                        {"center_m", d.at("center_m")},
                        {"size_mm", d.at("size_mm")},
                        {"support",
                         {{"sized_images", support.at("sized_images")},
                          {"well_seen_images", support.at("well_seen_images")},
                          {"sphere_rms_mm", support.at("sphere_rms_mm")},
                          {"points", d.at("points")},
                          {"required_points", support.at("required_points")},
                          {"size_stderr_mm", support.at("size_stderr_mm")}}},
                        {"per_view", per_view}};
    if (scored) {
      j["matched"] = truth.has_value();
      j["ground_truth"] = truth ? nlohmann::json(*truth) : nlohmann::json();
      if (truth)
        j["error_mm"] = d.at("size_mm").get<double>() - truth_[*truth].at("size_mm").get<double>();
    }
    setCluster(j, cluster);
    detections_.push_back(std::move(j));
  };
  if (sizing.contains("sized_fruitlets")) {
    std::size_t k = 0;
    for (const auto& d : sizing["sized_fruitlets"]) {
      add(d, true, k, truth_of_kept[k]);
      ++k;
    }
  }
  if (sizing.contains("unsupported_detections")) {
    std::size_t k = 0;
    for (const auto& d : sizing["unsupported_detections"]) add(d, false, k++, std::nullopt);
  }
}

void ViewerScene::addSeasonFruitlet(const Eigen::Vector3d& center_m, double size_mm,
                                    const std::string& label, const std::string& fate,
                                    double growth_mm_per_day, std::optional<int> cluster) {
  nlohmann::json j = {{"id", detections_.size()},       {"label", label},     {"kept", true},
                      {"center_m", vec3Json(center_m)}, {"size_mm", size_mm}, {"fate", fate}};
  if (std::isfinite(growth_mm_per_day)) j["growth_mm_per_day"] = growth_mm_per_day;
  setCluster(j, cluster);
  detections_.push_back(std::move(j));
}

nlohmann::json ViewerScene::toJson() const {
  nlohmann::json scene = {{"format", "fvp-viewer-scene"},
                          {"version", 1},
                          {"title", title_},
                          {"subtitle", subtitle_},
                          {"detections", detections_},
                          {"ground_truth", truth_},
                          {"cluster_regions", regions_},
                          {"tags", tags_},
                          {"cameras", cameras_},
                          {"chosen_candidates", candidates_}};
  if (intrinsics_)
    scene["intrinsics"] = {
        {"width_px", intrinsics_->width_px}, {"height_px", intrinsics_->height_px},
        {"fx_px", intrinsics_->fx_px},       {"fy_px", intrinsics_->fy_px},
        {"cx_px", intrinsics_->cx_px},       {"cy_px", intrinsics_->cy_px}};
  if (!voxels_.empty()) {
    std::array<std::int64_t, 3> lo, hi;
    lo.fill(std::numeric_limits<std::int64_t>::max());
    hi.fill(std::numeric_limits<std::int64_t>::min());
    for (const auto& v : voxels_)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], v[a]), hi[a] = std::max(hi[a], v[a]);
    for (int a = 0; a < 3; ++a)
      if (hi[a] - lo[a] > std::numeric_limits<std::uint16_t>::max())
        throw std::invalid_argument("ViewerScene: the fine voxels span more than 65536 voxels");
    std::vector<std::uint16_t> ijk;
    ijk.reserve(3 * voxels_.size());
    for (const auto& v : voxels_)
      for (int a = 0; a < 3; ++a) ijk.push_back(static_cast<std::uint16_t>(v[a] - lo[a]));
    scene["fine_voxels"] = {
        {"voxel_size_m", voxel_size_m_},
        {"origin_m", {lo[0] * voxel_size_m_, lo[1] * voxel_size_m_, lo[2] * voxel_size_m_}},
        {"count", voxels_.size()},
        {"ijk_u16_b64", base64Of(ijk)},
        {"roi_u8_b64", base64Of(voxel_roi_)}};
  }
  if (!mesh_triangles_.empty())
    scene["mesh"] = {{"vertex_count", mesh_vertices_m_.size() / 3},
                     {"triangle_count", mesh_triangles_.size() / 3},
                     {"vertices_f32_b64", base64Of(mesh_vertices_m_)},
                     {"triangles_u32_b64", base64Of(mesh_triangles_)}};
  return scene;
}

}  // namespace fvp::host::report
