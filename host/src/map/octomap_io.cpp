#include "fvp/host/map/octomap_io.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "fvp/host/core/atomic_file.h"

namespace fvp::host::map {
namespace {

constexpr unsigned kOcTreeDepth = 16;  // OctoMap's OcTree: 16-bit keys

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

// Checks the node bits of OctoMap's binary format from pos (OccupancyOcTreeBase::
// readBinaryNode): per inner node two bytes, two bits per child (00 unknown, 10 free, 01
// occupied, 11 inner). Counts the nodes; returns why the data is not a tree, or "".
// Recursion depth is at most the tree depth (16).
std::string checkBinaryNode(const std::string& bytes, std::size_t& pos, unsigned depth,
                            std::uint64_t& nodes) {
  if (bytes.size() - pos < 2) return "the tree data ends early";
  const auto low = static_cast<unsigned char>(bytes[pos]);
  const auto high = static_cast<unsigned char>(bytes[pos + 1]);
  pos += 2;
  const unsigned bits = low | (high << 8);
  bool any_child = false;
  for (unsigned i = 0; i < 8; ++i) {
    const unsigned code = (bits >> (2 * i)) & 3u;
    if (code == 0) continue;
    any_child = true;
    ++nodes;
    if (code != 3) continue;
    if (depth + 1 >= kOcTreeDepth) return "an inner node below the tree's depth of 16";
    const std::string why = checkBinaryNode(bytes, pos, depth + 1, nodes);
    if (!why.empty()) return why;
  }
  if (!any_child) return "an inner node without children";
  return "";
}

std::string checkBinaryTree(const std::string& bytes, std::size_t& pos, std::uint64_t& nodes) {
  nodes = 1;  // the root
  return checkBinaryNode(bytes, pos, 0, nodes);
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
  const std::string name = bt_path.string();
  const auto fail = [&](const std::string& why) -> void {
    throw std::runtime_error("reading coarse map " + name + ": " + why);
  };
  const std::string not_bt = "not a readable OctoMap binary (.bt) file";
  if (!std::filesystem::is_regular_file(bt_path)) fail(not_bt);
  std::ifstream in(bt_path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) fail(not_bt);

  // The header, as OctoMap's readBinary takes it: the text form (OcTree::writeBinaryConst) or
  // the legacy binary one (tree type 3, resolution, node count).
  std::istringstream s(bytes);
  std::string line;
  std::getline(s, line);
  const std::string magic = "# Octomap OcTree binary file";  // OctoMap's binaryFileHeader
  double res = 0.0;
  std::uint64_t size = 0;
  std::size_t data_start = 0;
  if (line.compare(0, magic.size(), magic) == 0) {
    std::string token, id;
    bool have_res = false, have_size = false, header_read = false;
    const auto skipLine = [&] { s.ignore(std::numeric_limits<std::streamsize>::max(), '\n'); };
    while (!header_read && s >> token) {
      if (token == "data") {
        skipLine();
        header_read = true;
      } else if (token == "id") {
        s >> id;
      } else if (token == "res") {
        have_res = static_cast<bool>(s >> res);
      } else if (token == "size") {
        std::string digits;
        s >> digits;
        have_size = !digits.empty() && digits.size() <= 10 &&
                    digits.find_first_not_of("0123456789") == std::string::npos;
        if (have_size) size = std::stoull(digits);
      } else {
        skipLine();  // comments and keywords OctoMap skips too
      }
    }
    if (!header_read || id.empty() || !have_res || !have_size)
      fail(not_bt + " (header without id, size, res and data)");
    data_start = s.eof() ? bytes.size() : static_cast<std::size_t>(s.tellg());
  } else {
    std::int32_t tree_type = 0;
    std::uint32_t legacy_size = 0;
    if (bytes.size() < 16) fail(not_bt);
    std::memcpy(&tree_type, bytes.data(), 4);
    std::memcpy(&res, bytes.data() + 4, 8);
    std::memcpy(&legacy_size, bytes.data() + 12, 4);
    if (tree_type != 3) fail(not_bt);
    size = legacy_size;
    data_start = 16;
  }
  // OctoMap keys are 16 bits from the tree's centre; a resolution outside this range makes
  // its key and coordinate arithmetic overflow or lose every digit.
  if (!(res >= kMinBtResolutionM && res <= kMaxBtResolutionM)) {
    std::ostringstream why;
    why << not_bt << " (resolution " << res << " m)";
    fail(why.str());
  }
  // OctoMap reads the node bits without checking for the end of the data or the tree's
  // depth: walk them first.
  std::size_t pos = data_start;
  std::uint64_t nodes = 0;
  if (size > 0) {
    const std::string why = checkBinaryTree(bytes, pos, nodes);
    if (!why.empty()) fail(not_bt + " (" + why + ")");
  }
  if (pos != bytes.size()) fail(not_bt + " (bytes after the tree data)");
  if (nodes != size)
    fail(not_bt + " (header says " + std::to_string(size) + " nodes, the data holds " +
         std::to_string(nodes) + ")");

  // OctoMap sees only what was checked, in its current header form.
  std::ostringstream canonical;
  canonical << std::setprecision(17) << magic << "\nid OcTree\nsize " << size << "\nres " << res
            << "\ndata\n";
  canonical.write(bytes.data() + data_start,
                  static_cast<std::streamsize>(bytes.size() - data_start));
  std::istringstream checked(canonical.str());
  auto tree = std::make_unique<octomap::OcTree>(res);
  if (!tree->readBinary(checked) || tree->size() != size) fail(not_bt);
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
