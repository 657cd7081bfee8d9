#include "fvp/host/map/roi_octree.h"

#include <algorithm>
#include <istream>
#include <limits>
#include <ostream>

namespace fvp::host::map {

// ---- RoiOcTreeNode -------------------------------------------------------------------

float RoiOcTreeNode::getMaxChildRoiLogOdds() const {
  float max_roi = -std::numeric_limits<float>::max();
  if (children == nullptr) return max_roi;
  for (unsigned i = 0; i < 8; ++i) {
    if (children[i] != nullptr) {
      max_roi = std::max(max_roi, static_cast<const RoiOcTreeNode*>(children[i])->roi_log_odds_);
    }
  }
  return max_roi;
}

void RoiOcTreeNode::updateOccupancyChildren() {
  setLogOdds(getMaxChildLogOdds());
  roi_log_odds_ = getMaxChildRoiLogOdds();
}

std::istream& RoiOcTreeNode::readData(std::istream& s) {
  s.read(reinterpret_cast<char*>(&value), sizeof(value));
  s.read(reinterpret_cast<char*>(&roi_log_odds_), sizeof(roi_log_odds_));
  return s;
}

std::ostream& RoiOcTreeNode::writeData(std::ostream& s) const {
  s.write(reinterpret_cast<const char*>(&value), sizeof(value));
  s.write(reinterpret_cast<const char*>(&roi_log_odds_), sizeof(roi_log_odds_));
  return s;
}

// ---- RoiOcTree -----------------------------------------------------------------------

RoiOcTree::StaticMemberInitializer RoiOcTree::roi_octree_member_init_;

RoiOcTree::StaticMemberInitializer::StaticMemberInitializer() {
  // OctoMap keeps the prototype for the lifetime of the program (as for its own types).
  auto* prototype = new RoiOcTree(0.1);
  prototype->clearKeyRays();
  octomap::AbstractOcTree::registerTreeType(prototype);
}

RoiOcTree::RoiOcTree(double resolution_m) : OccupancyOcTreeBase<RoiOcTreeNode>(resolution_m) {
  roi_octree_member_init_.ensureLinking();
}

RoiOcTreeNode* RoiOcTree::createRoot() {
  if (root == nullptr) {
    root = new RoiOcTreeNode();
    ++tree_size;
    size_changed = true;
  }
  return root;
}

RoiOcTreeNode* RoiOcTree::updateNodeAndRoi(const octomap::OcTreeKey& key, bool occupied,
                                           RoiUpdate roi, bool lazy_eval) {
  // OctoMap's early abort: nothing changes for a voxel already clamped in the update's
  // direction (search may return a pruned parent; its data is the voxel's).
  if (roi == RoiUpdate::kNone) {
    RoiOcTreeNode* leaf = search(key);
    if (leaf != nullptr && ((occupied && leaf->getLogOdds() >= clamping_thres_max) ||
                            (!occupied && leaf->getLogOdds() <= clamping_thres_min))) {
      return leaf;
    }
  }
  bool created_root = false;
  if (root == nullptr) {
    createRoot();
    created_root = true;
  }
  return updateNodeAndRoiRecurs(root, created_root, key, 0, occupied, roi, lazy_eval);
}

// OccupancyOcTreeBase::updateNodeRecurs with the ROI update added at the leaf, before any
// pruning on the way back up (a pruned leaf could no longer be told apart).
RoiOcTreeNode* RoiOcTree::updateNodeAndRoiRecurs(RoiOcTreeNode* node, bool node_just_created,
                                                 const octomap::OcTreeKey& key, unsigned depth,
                                                 bool occupied, RoiUpdate roi, bool lazy_eval) {
  if (depth < tree_depth) {
    const unsigned pos = octomap::computeChildIdx(key, static_cast<int>(tree_depth - 1 - depth));
    bool created_node = false;
    if (!nodeChildExists(node, pos)) {
      if (!nodeHasChildren(node) && !node_just_created) {
        expandNode(node);  // a pruned node: its children inherit its data
      } else {
        createNodeChild(node, pos);
        created_node = true;
      }
    }
    RoiOcTreeNode* leaf = updateNodeAndRoiRecurs(getNodeChild(node, pos), created_node, key,
                                                 depth + 1, occupied, roi, lazy_eval);
    if (lazy_eval) return leaf;
    if (pruneNode(node)) return node;
    node->updateOccupancyChildren();
    return leaf;
  }
  updateNodeLogOdds(node, occupied ? prob_hit_log : prob_miss_log);
  if (roi != RoiUpdate::kNone) {
    // Same arithmetic as updateNodeLogOdds (float add, then clamp).
    float v = node->getRoiLogOdds() + (roi == RoiUpdate::kHit ? prob_hit_log : prob_miss_log);
    v = std::clamp(v, clamping_thres_min, clamping_thres_max);
    node->setRoiLogOdds(v);
  }
  return node;
}

void RoiOcTree::updateInnerOccupancy() {
  if (root != nullptr) updateInnerOccupancyRecurs(root, 0);
}

void RoiOcTree::updateInnerOccupancyRecurs(RoiOcTreeNode* node, unsigned depth) {
  if (!nodeHasChildren(node)) return;
  if (depth < tree_depth) {
    for (unsigned i = 0; i < 8; ++i) {
      if (nodeChildExists(node, i)) updateInnerOccupancyRecurs(getNodeChild(node, i), depth + 1);
    }
  }
  node->updateOccupancyChildren();
}

}  // namespace fvp::host::map
