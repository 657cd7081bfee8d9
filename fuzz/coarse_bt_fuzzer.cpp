// readCoarseBt (host/src/map/octomap_io.cpp; OctoMap's binary .bt format) on a file holding
// the input. A tree it accepts must be a tree OctoMap can hold: resolution in range, no node
// below depth 16 (OctoMap itself reads deeper ones, and data past the file's end). It is then
// walked the way the maps use one: every leaf, its key and coordinate, a lookup of each.
#include <algorithm>

#include "fuzz_support.h"
#include "fvp/host/map/octomap_io.h"

namespace {

// The deepest node below `node` (at `depth`), walking every child.
unsigned maxDepth(const octomap::OcTree& tree, const octomap::OcTreeNode* node, unsigned depth) {
  unsigned deepest = depth;
  if (depth > tree.getTreeDepth()) return deepest;  // no further: reported by the caller
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i))
      deepest = std::max(deepest, maxDepth(tree, tree.getNodeChild(node, i), depth + 1));
  return deepest;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fz = fvp::fuzz;
  const std::filesystem::path path = fz::scratchDir() / "coarse.bt";
  fz::writeFile(path, data, size);
  std::unique_ptr<octomap::OcTree> tree;
  try {
    tree = fvp::host::map::readCoarseBt(path);
  } catch (const std::exception&) {
    return 0;  // rejected: expected for most inputs
  }
  const double res = tree->getResolution();
  if (!(res >= fvp::host::map::kMinBtResolutionM && res <= fvp::host::map::kMaxBtResolutionM) ||
      (tree->getRoot() != nullptr && maxDepth(*tree, tree->getRoot(), 0) > tree->getTreeDepth())) {
    std::fprintf(stderr, "fvp fuzz: readCoarseBt accepted a tree OctoMap cannot hold\n");
    std::abort();
  }
  std::size_t leaves = 0;
  for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
    const octomap::OcTreeNode* node = tree->search(it.getKey(), it.getDepth());
    if (node == nullptr || it.getDepth() > tree->getTreeDepth()) {
      std::fprintf(stderr, "fvp fuzz: a leaf of the tree read is not found again\n");
      std::abort();
    }
    (void)tree->isNodeOccupied(*node);
    (void)it.getCoordinate();
    ++leaves;
  }
  if (leaves > tree->size()) std::abort();
  double x, y, z;
  tree->getMetricMin(x, y, z);
  tree->getMetricMax(x, y, z);
  return 0;
}
