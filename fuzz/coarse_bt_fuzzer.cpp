// readCoarseBt (host/src/map/octomap_io.cpp; OctoMap's binary .bt format) on a file holding
// the input. A tree it accepts is walked the way the maps use one: every leaf, its key and
// coordinate, and a lookup of each.
#include "fuzz_support.h"
#include "fvp/host/map/octomap_io.h"

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
