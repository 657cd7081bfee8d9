#include "fvp/host/map/octomap_io.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fvp/host/core/atomic_file.h"

namespace fvp::host::map {
namespace {

// ColorOcTree keeps its root protected; building a tree node by node (same structure as the
// source, pruned leaves included) needs it. The type written to files stays "ColorOcTree".
class ColorOcTreeBuilder : public octomap::ColorOcTree {
 public:
  using ColorOcTree::ColorOcTree;
  octomap::ColorOcTreeNode* createRoot() {
    root = new octomap::ColorOcTreeNode();
    ++tree_size;
    size_changed = true;
    return root;
  }
};

template <typename SrcTree, typename DstTree>
void copySensorModel(const SrcTree& src, DstTree& dst) {
  dst.setProbHit(src.getProbHit());
  dst.setProbMiss(src.getProbMiss());
  dst.setClampingThresMin(src.getClampingThresMin());
  dst.setClampingThresMax(src.getClampingThresMax());
  dst.setOccupancyThres(src.getOccupancyThres());
}

// Copies the node structure of src below s into dst below d; copy_data(s, d) copies one
// node's payload. Recursion depth is the tree depth (16).
template <typename SrcTree, typename DstTree, typename CopyData>
void copyNodes(const SrcTree& src, const typename SrcTree::NodeType* s, DstTree& dst,
               typename DstTree::NodeType* d, const CopyData& copy_data) {
  copy_data(*s, *d);
  if (!src.nodeHasChildren(s)) return;
  for (unsigned i = 0; i < 8; ++i) {
    if (src.nodeChildExists(s, i)) {
      copyNodes(src, src.getNodeChild(s, i), dst, dst.createNodeChild(d, i), copy_data);
    }
  }
}

}  // namespace

octomap::ColorOcTreeNode::Color encodeRoiColor(float roi_log_odds) {
  if (std::isnan(roi_log_odds)) roi_log_odds = 0.0f;  // never stored; keep lround defined
  const float scaled = std::clamp(roi_log_odds * kRoiColorScale, -32768.0f, 32767.0f);
  long q = std::lround(scaled);
  // Keep the sign class: a tiny positive value stays positive, a tiny negative one <= 0.
  if (roi_log_odds > 0.0f) q = std::max(q, 1L);
  if (!(roi_log_odds > 0.0f)) q = std::min(q, 0L);
  const auto u = static_cast<unsigned>(q + kRoiColorOffset);
  return {roi_log_odds > 0.0f ? kRoiRed : kNonRoiRed, static_cast<std::uint8_t>(u >> 8),
          static_cast<std::uint8_t>(u & 0xffu)};
}

float decodeRoiColor(const octomap::ColorOcTreeNode::Color& color) {
  const int u = (int{color.g} << 8) | int{color.b};
  return static_cast<float>(u - kRoiColorOffset) / kRoiColorScale;
}

void writeCoarseBt(const octomap::OcTree& tree, const std::filesystem::path& bt_path) {
  writeFileAtomically(bt_path, "coarse map (.bt)",
                      [&](std::ostream& out) { return tree.writeBinaryConst(out); });
}

std::unique_ptr<octomap::OcTree> readCoarseBt(const std::filesystem::path& bt_path) {
  auto tree = std::make_unique<octomap::OcTree>(0.1);  // resolution comes from the file
  if (!std::filesystem::is_regular_file(bt_path) || !tree->readBinary(bt_path.string())) {
    throw std::runtime_error("reading coarse map " + bt_path.string() +
                             ": not a readable OctoMap binary (.bt) file");
  }
  return tree;
}

std::unique_ptr<octomap::ColorOcTree> toColorOcTree(const RoiOcTree& tree) {
  auto out = std::make_unique<ColorOcTreeBuilder>(tree.getResolution());
  copySensorModel(tree, *out);
  if (tree.getRoot() != nullptr) {
    copyNodes(tree, tree.getRoot(), *out, out->createRoot(),
              [](const RoiOcTreeNode& s, octomap::ColorOcTreeNode& d) {
                d.setLogOdds(s.getLogOdds());
                d.setColor(encodeRoiColor(s.getRoiLogOdds()));
              });
  }
  return out;
}

std::unique_ptr<RoiOcTree> fromColorOcTree(const octomap::ColorOcTree& tree) {
  auto out = std::make_unique<RoiOcTree>(tree.getResolution());
  copySensorModel(tree, *out);
  if (tree.getRoot() != nullptr) {
    copyNodes(tree, tree.getRoot(), *out, out->createRoot(),
              [](const octomap::ColorOcTreeNode& s, RoiOcTreeNode& d) {
                d.setLogOdds(s.getLogOdds());
                d.setRoiLogOdds(decodeRoiColor(s.getColor()));
              });
  }
  return out;
}

void writeFineOt(const RoiOcTree& tree, const std::filesystem::path& ot_path) {
  const std::unique_ptr<octomap::ColorOcTree> color = toColorOcTree(tree);
  writeFileAtomically(ot_path, "fine map (.ot)",
                      [&](std::ostream& out) { return color->write(out); });
}

std::unique_ptr<RoiOcTree> readFineOt(const std::filesystem::path& ot_path) {
  const std::string name = ot_path.string();
  if (!std::filesystem::is_regular_file(ot_path)) {
    throw std::runtime_error("reading fine map " + name + ": no such file");
  }
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(name));
  if (tree == nullptr) {
    throw std::runtime_error("reading fine map " + name + ": not a readable OctoMap .ot file");
  }
  if (auto* roi = dynamic_cast<RoiOcTree*>(tree.get())) {
    tree.release();
    return std::unique_ptr<RoiOcTree>(roi);
  }
  if (const auto* color = dynamic_cast<const octomap::ColorOcTree*>(tree.get())) {
    return fromColorOcTree(*color);
  }
  throw std::runtime_error("reading fine map " + name + ": holds a " + tree->getTreeType() +
                           ", expected ColorOcTree or RoiOcTree");
}

}  // namespace fvp::host::map
