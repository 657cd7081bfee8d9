#include "fvp/robot/workspace_tree.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <numbers>
#include <ostream>
#include <random>
#include <sstream>

#include "fvp/host/core/atomic_file.h"
#include "fvp/robot/ur5_kinematics.h"

namespace fvp::robot {
namespace {

constexpr char kMagic[8] = {'F', 'V', 'P', 'W', 'S', 'T', '0', '2'};
constexpr std::int64_t kChunk = 1 << 16;  // samples per random stream

std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t h = 1469598103934665603ull) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    h ^= bytes[i];
    h *= 1099511628211ull;
  }
  return h;
}

template <typename T>
void put(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
bool get(const std::string& in, std::size_t& pos, T& value) {
  if (pos + sizeof(T) > in.size()) return false;
  std::memcpy(&value, in.data() + pos, sizeof(T));
  pos += sizeof(T);
  return true;
}

}  // namespace

std::string WorkspaceTree::cacheKey(const ArmModel& arm) {
  const ArmConfig& c = arm.config();
  std::ostringstream key;
  key << std::setprecision(17) << "fvp-workspace-tree v2; dh";
  for (int i = 0; i < 6; ++i)
    key << ' ' << Ur5Kinematics::kA_m[i] << ',' << Ur5Kinematics::kD_m[i] << ','
        << Ur5Kinematics::kAlpha_rad[i];
  key << "; lower " << arm.lowerLimits().transpose() << "; upper " << arm.upperLimits().transpose()
      << "; slider " << c.slider_origin_m.transpose() << ' ' << c.slider_yaw_deg << ' '
      << c.base_yaw_deg << "; hand_eye " << c.hand_eye_translation_m.transpose() << ' '
      << c.hand_eye_rpy_deg.transpose() << "; camera_body " << c.camera_body_radius_m << "; ground "
      << c.ground_z_m << "; samples " << c.workspace_samples << "; resolution "
      << c.workspace_resolution_m << "; bins " << c.workspace_direction_bins << "; min_count "
      << c.workspace_min_count << "; seed " << c.workspace_seed;
  return key.str();
}

std::filesystem::path WorkspaceTree::cachePath(const ArmModel& arm) {
  const std::string& dir = arm.config().workspace_cache_dir;
  if (dir.empty()) return {};
  const std::string key = cacheKey(arm);
  std::ostringstream name;
  name << "workspace_" << std::hex << std::setw(16) << std::setfill('0')
       << fnv1a(key.data(), key.size()) << ".bin";
  return std::filesystem::path(dir) / name.str();
}

WorkspaceTree WorkspaceTree::build(const ArmModel& arm) {
  const ArmConfig& c = arm.config();
  WorkspaceTree tree;
  tree.key_ = cacheKey(arm);
  tree.resolution_m_ = c.workspace_resolution_m;
  tree.bins_per_edge_ = c.workspace_direction_bins;
  tree.min_count_ = c.workspace_min_count;
  // The grid lives in the slider's frame (x along the travel, z up). The slider only
  // translates the UR5, so each sample of the six arm joints is counted once, with the
  // carriage centred, into an arm grid, and the arm grid is then swept along the travel:
  // every configuration counts at every slider position, not just one random one.
  const double yaw = c.slider_yaw_deg * std::numbers::pi / 180.0;
  tree.slider_origin_m_ = c.slider_origin_m;
  tree.slider_yaw_rad_ = yaw;
  tree.R_slider_world_ = Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const double r = tree.resolution_m_;
  const double reach = kUr5ReachM + c.hand_eye_translation_m.norm() + c.camera_body_radius_m;
  const int arm_cells = static_cast<int>(std::ceil(2.0 * reach / r));
  const Eigen::Vector3d arm_origin(-0.5 * arm_cells * r, -0.5 * arm_cells * r,
                                   -0.5 * arm_cells * r);  // slider frame, carriage centred
  const int shifts = static_cast<int>(std::lround(c.slider_travel_m / r));  // sweep steps
  tree.dims_ = {arm_cells + shifts, arm_cells, arm_cells};
  tree.origin_m_ = arm_origin - Eigen::Vector3d(0.5 * shifts * r, 0.0, 0.0);
  const std::size_t bins = static_cast<std::size_t>(tree.directionBins());
  const std::size_t arm_total = static_cast<std::size_t>(arm_cells) * arm_cells * arm_cells;

  // Each sample's arm-grid slot first (in parallel, one random stream per chunk, so the
  // result is the same on any number of threads), then one serial counting pass.
  const std::int64_t n = c.workspace_samples;
  std::vector<std::uint32_t> slot(static_cast<std::size_t>(n));
  const std::int64_t chunks = (n + kChunk - 1) / kChunk;
  const JointVector lo = arm.lowerLimits(), hi = arm.upperLimits();
  constexpr std::uint32_t kNone = 0xffffffffu;
#pragma omp parallel for schedule(dynamic, 4)
  for (std::int64_t chunk = 0; chunk < chunks; ++chunk) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(c.workspace_seed) * 0x9E3779B97F4A7C15ull +
                        static_cast<std::uint64_t>(chunk));
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const std::int64_t end = std::min(n, (chunk + 1) * kChunk);
    for (std::int64_t i = chunk * kChunk; i < end; ++i) {
      JointVector q;
      q[0] = 0.0;
      for (int j = 1; j < kArmJoints; ++j) q[j] = lo[j] + (hi[j] - lo[j]) * unit(rng);
      Eigen::Isometry3d T_wc;
      const LinkCapsules links = arm.linkCapsules(q, &T_wc);
      std::uint32_t s = kNone;
      if (!arm.selfOrStaticCollision(links)) {
        const Eigen::Vector3d p = tree.R_slider_world_ * (T_wc.translation() - c.slider_origin_m);
        const Eigen::Vector3d u = (p - arm_origin) / r;
        const Eigen::Vector3i k = u.array().floor().cast<int>();
        if ((k.array() >= 0).all() && (k.array() < arm_cells).all()) {
          const std::size_t cell =
              (static_cast<std::size_t>(k.z()) * arm_cells + k.y()) * arm_cells + k.x();
          s = static_cast<std::uint32_t>(
              cell * bins + tree.directionBin(tree.R_slider_world_ * T_wc.linear().col(2)));
        }
      }
      slot[static_cast<std::size_t>(i)] = s;
    }
  }
  std::vector<std::uint32_t> arm_counts(arm_total * bins, 0);
  for (const std::uint32_t s : slot) {
    if (s != kNone) ++arm_counts[s];
  }
  slot = {};
  // Sweep along x: world cell x = arm cell x + shift, shift in [0, shifts] (a running sum
  // over a window of shifts + 1 arm cells).
  const std::size_t cells = static_cast<std::size_t>(tree.dims_.prod());
  tree.counts_.assign(cells * bins, 0);
  const int wx = tree.dims_.x();
  for (int z = 0; z < arm_cells; ++z) {
    for (int y = 0; y < arm_cells; ++y) {
      for (std::size_t b = 0; b < bins; ++b) {
        std::uint64_t window = 0;
        for (int x = 0; x < wx; ++x) {
          if (x < arm_cells)
            window +=
                arm_counts[((static_cast<std::size_t>(z) * arm_cells + y) * arm_cells + x) * bins +
                           b];
          const int leaving = x - shifts - 1;
          if (leaving >= 0 && leaving < arm_cells)
            window -=
                arm_counts[((static_cast<std::size_t>(z) * arm_cells + y) * arm_cells + leaving) *
                               bins +
                           b];
          const std::size_t cell = (static_cast<std::size_t>(z) * arm_cells + y) * wx + x;
          tree.counts_[cell * bins + b] =
              static_cast<std::uint16_t>(std::min<std::uint64_t>(window, 0xffff));
        }
      }
    }
  }
  tree.finish();
  return tree;
}

void WorkspaceTree::finish() {
  const std::size_t bins = static_cast<std::size_t>(directionBins());
  const std::size_t cells = static_cast<std::size_t>(dims_.prod());
  cell_any_.assign(cells, 0);
  for (std::size_t cell = 0; cell < cells; ++cell) {
    for (std::size_t b = 0; b < bins; ++b)
      cell_any_[cell] |= counts_[cell * bins + b] >= min_count_ ? 1 : 0;
  }
}

void WorkspaceTree::save(const std::filesystem::path& path) const {
  std::string bytes(kMagic, sizeof(kMagic));
  put(bytes, static_cast<std::uint32_t>(key_.size()));
  bytes += key_;
  for (int i = 0; i < 3; ++i) put(bytes, slider_origin_m_[i]);
  put(bytes, slider_yaw_rad_);
  for (int i = 0; i < 3; ++i) put(bytes, origin_m_[i]);
  put(bytes, resolution_m_);
  for (int i = 0; i < 3; ++i) put(bytes, static_cast<std::int32_t>(dims_[i]));
  put(bytes, static_cast<std::int32_t>(bins_per_edge_));
  put(bytes, static_cast<std::int32_t>(min_count_));
  put(bytes, static_cast<std::uint64_t>(counts_.size()));
  bytes.append(reinterpret_cast<const char*>(counts_.data()),
               counts_.size() * sizeof(std::uint16_t));
  put(bytes, fnv1a(bytes.data(), bytes.size()));
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  host::writeFileAtomically(path, "workspace tree cache", bytes);
}

std::optional<WorkspaceTree> WorkspaceTree::load(const std::filesystem::path& path,
                                                 const std::string& expected_key,
                                                 std::string* why) {
  const auto fail = [&](const std::string& reason) -> std::optional<WorkspaceTree> {
    if (why != nullptr) *why = reason;
    return std::nullopt;
  };
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail("cannot open " + path.string());
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < sizeof(kMagic) + sizeof(std::uint64_t) ||
      std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    return fail("not a workspace tree file");
  std::uint64_t stored_sum = 0;
  std::memcpy(&stored_sum, bytes.data() + bytes.size() - sizeof(stored_sum), sizeof(stored_sum));
  if (fnv1a(bytes.data(), bytes.size() - sizeof(stored_sum)) != stored_sum)
    return fail("checksum mismatch (corrupt or truncated)");
  WorkspaceTree tree;
  std::size_t pos = sizeof(kMagic);
  std::uint32_t key_size = 0;
  if (!get(bytes, pos, key_size) || pos + key_size > bytes.size()) return fail("truncated key");
  tree.key_.assign(bytes.data() + pos, key_size);
  pos += key_size;
  if (tree.key_ != expected_key) return fail("built for other parameters");
  std::int32_t dims[3], edge = 0, min_count = 0;
  std::uint64_t entries = 0;
  bool ok = true;
  for (int i = 0; i < 3; ++i) ok = ok && get(bytes, pos, tree.slider_origin_m_[i]);
  ok = ok && get(bytes, pos, tree.slider_yaw_rad_);
  for (int i = 0; i < 3; ++i) ok = ok && get(bytes, pos, tree.origin_m_[i]);
  ok = ok && get(bytes, pos, tree.resolution_m_);
  for (int i = 0; i < 3; ++i) ok = ok && get(bytes, pos, dims[i]);
  ok = ok && get(bytes, pos, edge) && get(bytes, pos, min_count) && get(bytes, pos, entries);
  if (!ok || pos + sizeof(stored_sum) > bytes.size() || edge < 1 || edge > 64 || min_count < 1 ||
      dims[0] < 1 || dims[1] < 1 || dims[2] < 1)
    return fail("bad header");
  // The grid's placement must be finite and its cells of positive size: queries divide by
  // the resolution and rotate by the yaw.
  if (!tree.slider_origin_m_.allFinite() || !std::isfinite(tree.slider_yaw_rad_) ||
      !tree.origin_m_.allFinite() || !std::isfinite(tree.resolution_m_) ||
      !(tree.resolution_m_ > 0.0))
    return fail("bad header (non-finite grid placement or resolution)");
  tree.dims_ = {dims[0], dims[1], dims[2]};
  tree.bins_per_edge_ = edge;
  tree.min_count_ = min_count;
  // The counts the rest of the file holds bound the cells before they are multiplied (the
  // product of three int32 overflows), and cell indices are ints.
  const std::uint64_t held = (bytes.size() - pos - sizeof(stored_sum)) / sizeof(std::uint16_t);
  const std::uint64_t bins = static_cast<std::uint64_t>(tree.directionBins());
  std::uint64_t cells = 1;
  for (int i = 0; i < 3; ++i) {
    if (static_cast<std::uint64_t>(dims[i]) > held / (cells * bins))
      return fail("size does not match its header");
    cells *= static_cast<std::uint64_t>(dims[i]);
  }
  if (cells > static_cast<std::uint64_t>(std::numeric_limits<int>::max()) ||
      entries != cells * bins ||
      pos + entries * sizeof(std::uint16_t) + sizeof(stored_sum) != bytes.size())
    return fail("size does not match its header");
  tree.counts_.resize(entries);
  std::memcpy(tree.counts_.data(), bytes.data() + pos, entries * sizeof(std::uint16_t));
  tree.R_slider_world_ =
      Eigen::AngleAxisd(-tree.slider_yaw_rad_, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  tree.finish();
  tree.from_cache_ = true;
  return tree;
}

WorkspaceTree WorkspaceTree::loadOrBuild(const ArmModel& arm, std::ostream& log) {
  const std::filesystem::path path = cachePath(arm);
  if (!path.empty() && std::filesystem::exists(path)) {
    std::string why;
    if (auto tree = load(path, cacheKey(arm), &why)) return std::move(*tree);
    log << "warning: workspace tree cache " << path << " not used (" << why << "); rebuilding\n";
  }
  WorkspaceTree tree = build(arm);
  if (!path.empty()) {
    try {
      tree.save(path);
    } catch (const std::exception& e) {
      log << "warning: cannot write the workspace tree cache: " << e.what() << '\n';
    }
  }
  return tree;
}

int WorkspaceTree::cellIndex(const Eigen::Vector3d& p_world) const {
  const Eigen::Vector3d p = R_slider_world_ * (p_world - slider_origin_m_);
  const Eigen::Vector3d u = (p - origin_m_) / resolution_m_;
  // Compared as doubles before the cast: a far (or NaN) point does not fit an int.
  if (!(u.array() >= 0.0).all() || !(u.array() < dims_.cast<double>().array()).all()) return -1;
  const Eigen::Vector3i k = u.array().floor().cast<int>();
  return (k.z() * dims_.y() + k.y()) * dims_.x() + k.x();
}

int WorkspaceTree::directionBin(const Eigen::Vector3d& d) const {
  // Cube map: the dominant axis and its sign pick the face, the other two coordinates over
  // the dominant one the cell on it.
  int axis = 0;
  d.cwiseAbs().maxCoeff(&axis);
  const int face = 2 * axis + (d[axis] < 0.0 ? 1 : 0);
  const double m = std::abs(d[axis]);
  const double u = d[(axis + 1) % 3] / m, v = d[(axis + 2) % 3] / m;  // in [-1, 1]
  const int k = bins_per_edge_;
  const int iu = std::clamp(static_cast<int>((u + 1.0) * 0.5 * k), 0, k - 1);
  const int iv = std::clamp(static_cast<int>((v + 1.0) * 0.5 * k), 0, k - 1);
  return (face * k + iu) * k + iv;
}

bool WorkspaceTree::reachable(const Eigen::Isometry3d& T_world_camera) const {
  return count(T_world_camera.translation(), T_world_camera.linear().col(2)) >= min_count_;
}

bool WorkspaceTree::reachablePosition(const Eigen::Vector3d& p_world_m) const {
  const int cell = cellIndex(p_world_m);
  return cell >= 0 && cell_any_[static_cast<std::size_t>(cell)] != 0;
}

int WorkspaceTree::count(const Eigen::Vector3d& p_world_m,
                         const Eigen::Vector3d& view_dir_world) const {
  const int cell = cellIndex(p_world_m);
  if (cell < 0 || !(view_dir_world.squaredNorm() > 0.0)) return 0;
  return counts_[static_cast<std::size_t>(cell) * static_cast<std::size_t>(directionBins()) +
                 static_cast<std::size_t>(directionBin(R_slider_world_ * view_dir_world))];
}

std::uint64_t WorkspaceTree::nonEmptyBins() const {
  return static_cast<std::uint64_t>(std::count_if(
      counts_.begin(), counts_.end(), [&](std::uint16_t c) { return c >= min_count_; }));
}

std::string defaultCacheDir() {
  if (const char* dir = std::getenv("FVP_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return (std::filesystem::path(xdg) / "fvp").string();
  if (const char* home = std::getenv("HOME"); home && *home)
    return (std::filesystem::path(home) / ".cache" / "fvp").string();
  return (std::filesystem::temp_directory_path() / "fvp-cache").string();
}

}  // namespace fvp::robot
