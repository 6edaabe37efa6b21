#include "maximal_workspace/io/region_label_octree.h"

#include "io/octree_pyramid.h"

#include <istream>
#include <ostream>

namespace maximal_workspace {

std::istream& RegionLabelNode::readData(std::istream& stream) {
  OcTreeNode::readData(stream);
  // Native byte order, as OctoMap stores the occupancy.
  stream.read(reinterpret_cast<char*>(&label_), sizeof label_);
  return stream;
}

std::ostream& RegionLabelNode::writeData(std::ostream& stream) const {
  OcTreeNode::writeData(stream);
  stream.write(reinterpret_cast<const char*>(&label_), sizeof label_);
  return stream;
}

RegionLabelOcTree::FactoryRegistration RegionLabelOcTree::factory_registration_;

RegionLabelOcTree::FactoryRegistration::FactoryRegistration() {
  // The factory keeps the prototype for the life of the program.
  auto* prototype = new RegionLabelOcTree(0.1);
  prototype->clearKeyRays();
  AbstractOcTree::registerTreeType(prototype);
}

RegionLabelOcTree::RegionLabelOcTree(double resolution) : OccupancyOcTreeBase<RegionLabelNode>(resolution) {
  factory_registration_.ensureLinking();
}

void RegionLabelOcTree::buildFrom(const KeyPyramid& pyramid) {
  const std::array<std::uint32_t, 3> everything = {0, 0, 0};
  if (root != nullptr || pyramid.value(KeyPyramid::kTreeDepth, everything) == KeyPyramid::kEmpty) return;
  const float occupied = getClampingThresMaxLog();
  root = new RegionLabelNode();
  root->setLogOdds(occupied);
  ++tree_size;
  buildFromPyramid(
      root, pyramid, KeyPyramid::kTreeDepth, everything,
      [this](RegionLabelNode* node, unsigned index) { return createNodeChild(node, index); },
      [occupied](RegionLabelNode* node, std::int32_t label) {
        node->setLogOdds(occupied);
        node->setLabel(label);
      },
      [occupied](RegionLabelNode* node) { node->setLogOdds(occupied); });
  size_changed = true;
}

bool RegionLabelOcTree::isNodeCollapsible(const RegionLabelNode* node) const {
  if (!nodeChildExists(node, 0)) return false;
  const RegionLabelNode* first = getNodeChild(node, 0);
  for (unsigned int i = 0; i < 8; ++i) {
    if (!nodeChildExists(node, i)) return false;
    const RegionLabelNode* child = getNodeChild(node, i);
    if (nodeHasChildren(child) || child->getLogOdds() != first->getLogOdds() || child->label() != first->label()) {
      return false;
    }
  }
  return true;
}

}  // namespace maximal_workspace
