#pragma once
// An OctoMap occupancy octree whose nodes also carry a region label (a region id of
// WorkspaceAnalysis::regions, -1 for none), saved as a .ot file that
// octomap::AbstractOcTree::read() turns back into this type.

#include <cstdint>
#include <iosfwd>
#include <string>

#include <octomap/OcTreeNode.h>
#include <octomap/OccupancyOcTreeBase.h>


namespace maximal_workspace {

class KeyPyramid;  // the library's own way to fill a tree already pruned

constexpr std::int32_t kNoRegionLabel = -1;

class RegionLabelNode : public octomap::OcTreeNode {
 public:
  std::int32_t label() const { return label_; }
  void setLabel(std::int32_t label) { label_ = label; }

  // OctoMap calls these through the node type: the label travels with the occupancy when
  // nodes are copied, expanded, compared, or serialised.
  void copyData(const RegionLabelNode& from) {
    OcTreeNode::copyData(from);
    label_ = from.label_;
  }
  bool operator==(const RegionLabelNode& other) const { return value == other.value && label_ == other.label_; }
  std::istream& readData(std::istream& stream);
  std::ostream& writeData(std::ostream& stream) const;

 private:
  // Inner nodes that were not collapsed keep kNoRegionLabel: their children differ.
  std::int32_t label_ = kNoRegionLabel;
};

class RegionLabelOcTree : public octomap::OccupancyOcTreeBase<RegionLabelNode> {
 public:
  explicit RegionLabelOcTree(double resolution);

  RegionLabelOcTree* create() const override { return new RegionLabelOcTree(resolution); }
  std::string getTreeType() const override { return "RegionLabelOcTree"; }

  // Eight children collapse only when they are all leaves with equal occupancy and equal
  // labels; OctoMap's pruneNode then copies the first child's data, label included, into
  // the parent, so prune() never loses a label.
  bool isNodeCollapsible(const RegionLabelNode* node) const override;

  // Fills an empty tree from a pyramid of labels, already pruned (src/io/octree_pyramid.h):
  // occupied leaves carrying their label, inner nodes occupied with kNoRegionLabel.
  void buildFrom(const KeyPyramid& pyramid);

 private:
  // Registers a prototype with AbstractOcTree's factory when the library is loaded, so
  // AbstractOcTree::read() recognises "RegionLabelOcTree" files.
  class FactoryRegistration {
   public:
    FactoryRegistration();
    // Called from the constructor so the linker keeps the registration object.
    void ensureLinking() const {}
  };
  static FactoryRegistration factory_registration_;
};

}  // namespace maximal_workspace
