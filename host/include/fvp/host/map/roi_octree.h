// The fine map of the octomap engine: an OctoMap occupancy octree whose nodes carry a second
// log-odds, the ROI log-odds (as octomap_vpp's RoiOcTree does for the ROI viewpoint planner).
// Registered with OctoMap like its own derived trees (ColorOcTree, OcTreeStamped), so
// octomap::AbstractOcTree::read() returns a RoiOcTree for an .ot file whose id is "RoiOcTree"
// in any program linked with fvp_host_map. OctoMap's own tools do not know this type; the
// engine therefore exports the fine map as a ColorOcTree (octomap_io.h, docs/maps.md).
#pragma once

#include <octomap/OcTreeNode.h>
#include <octomap/OccupancyOcTreeBase.h>

#include <iosfwd>
#include <string>

namespace fvp::host::map {

class RoiOcTreeNode : public octomap::OcTreeNode {
 public:
  RoiOcTreeNode() = default;
  RoiOcTreeNode(const RoiOcTreeNode& rhs) : OcTreeNode(rhs), roi_log_odds_(rhs.roi_log_odds_) {}

  // OctoMap's templates call these by the node type (pruning compares nodes, expansion and
  // pruning copy them), so they must cover the ROI value too.
  bool operator==(const RoiOcTreeNode& rhs) const {
    return rhs.value == value && rhs.roi_log_odds_ == roi_log_odds_;
  }
  void copyData(const RoiOcTreeNode& from) {
    OcTreeNode::copyData(from);
    roi_log_odds_ = from.roi_log_odds_;
  }

  /// ROI log-odds; 0 until an end point lands in the voxel. ROI when > 0.
  float getRoiLogOdds() const { return roi_log_odds_; }
  void setRoiLogOdds(float log_odds) { roi_log_odds_ = log_odds; }
  bool isRoi() const { return roi_log_odds_ > 0.0f; }

  /// Inner nodes: occupancy and ROI both the maximum over the children (conservative,
  /// like OcTreeNode::updateOccupancyChildren).
  void updateOccupancyChildren();
  float getMaxChildRoiLogOdds() const;

  /// File I/O (.ot): occupancy log-odds then ROI log-odds, each a native float.
  std::istream& readData(std::istream& s);
  std::ostream& writeData(std::ostream& s) const;

 private:
  float roi_log_odds_ = 0.0f;
};

class RoiOcTree : public octomap::OccupancyOcTreeBase<RoiOcTreeNode> {
 public:
  /// What an end point says about a voxel's ROI log-odds in one scan.
  enum class RoiUpdate { kNone, kHit, kMiss };

  explicit RoiOcTree(double resolution_m);

  RoiOcTree* create() const override { return new RoiOcTree(resolution); }
  std::string getTreeType() const override { return "RoiOcTree"; }

  /// One update of voxel `key`: occupancy +hit or +miss log-odds (OctoMap's updateNode,
  /// clamped), and the ROI log-odds +hit / +miss / unchanged with the same sensor model and
  /// clamping. Pruning and inner nodes as OctoMap's updateNode with lazy_eval (when lazy,
  /// call updateInnerOccupancy() afterwards). Returns the updated leaf, or its pruned
  /// parent when the update made the parent collapsible.
  RoiOcTreeNode* updateNodeAndRoi(const octomap::OcTreeKey& key, bool occupied, RoiUpdate roi,
                                  bool lazy_eval = false);

  /// Recomputes the inner nodes' occupancy and ROI (hides the base version, which would
  /// leave inner ROI values stale; ColorOcTree does the same).
  void updateInnerOccupancy();

  /// Creates the root of an empty tree (for building a tree node by node from another).
  RoiOcTreeNode* createRoot();

 protected:
  RoiOcTreeNode* updateNodeAndRoiRecurs(RoiOcTreeNode* node, bool node_just_created,
                                        const octomap::OcTreeKey& key, unsigned depth,
                                        bool occupied, RoiUpdate roi, bool lazy_eval);
  void updateInnerOccupancyRecurs(RoiOcTreeNode* node, unsigned depth);

  /// Registers the type with AbstractOcTree (OctoMap's StaticMemberInitializer pattern).
  class StaticMemberInitializer {
   public:
    StaticMemberInitializer();
    void ensureLinking() {}
  };
  static StaticMemberInitializer roi_octree_member_init_;
};

}  // namespace fvp::host::map
