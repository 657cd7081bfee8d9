// WorkspaceTree::load (robot/src/workspace_tree.cpp; the workspace-tree cache file) on a file
// holding the input. The harness makes the input's checksum right (its last 8 bytes: FNV-1a
// of the rest, as save() writes it) and expects the key the file holds, so inputs reach the
// header and counts instead of stopping at the checksum. A tree it loads is queried.
#include <cstring>

#include "fuzz_support.h"
#include "fvp/robot/workspace_tree.h"

namespace {

std::uint64_t fnv1a(const char* bytes, std::size_t size) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= static_cast<unsigned char>(bytes[i]);
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fz = fvp::fuzz;
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (bytes.size() >= 16) {
    const std::uint64_t sum = fnv1a(bytes.data(), bytes.size() - 8);
    std::memcpy(bytes.data() + bytes.size() - 8, &sum, 8);
  }
  // The key as load() finds it: after the 8-byte magic, a uint32 size and the text.
  std::string key;
  std::uint32_t key_size = 0;
  if (bytes.size() >= 12) {
    std::memcpy(&key_size, bytes.data() + 8, 4);
    if (key_size <= bytes.size() - 12) key.assign(bytes.data() + 12, key_size);
  }
  const std::filesystem::path path = fz::scratchDir() / "workspace.bin";
  fz::writeFile(path, bytes);
  std::string why;
  const std::optional<fvp::robot::WorkspaceTree> tree =
      fvp::robot::WorkspaceTree::load(path, key, &why);
  if (!tree) return 0;  // rejected: expected for most inputs
  (void)tree->nonEmptyBins();
  // Points around the slider and a few view directions, as the planners ask.
  for (const double x : {-1.0, 0.0, 0.3, 1.0})
    for (const double z : {-0.5, 0.0, 0.5}) {
      const Eigen::Vector3d p(x, 0.1, z);
      (void)tree->reachablePosition(p);
      (void)tree->count(p, Eigen::Vector3d(0.0, 0.0, 1.0));
      (void)tree->count(p, Eigen::Vector3d(1.0, -2.0, 0.5));
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.translation() = p;
      (void)tree->reachable(T);
    }
  return 0;
}
