#include "workspace/block_storage.h"

#include <algorithm>

namespace maximal_workspace {

CellCode* CodeMap::addPage(std::uint64_t block) {
  const std::uint32_t index = pages_.add();
  entry_[block] = index;
  return pages_.page(index);
}

void LabelLayer::addPage(std::uint64_t block, std::uint32_t components) {
  const std::uint32_t index = pages_.add();
  block_label_[block] = kPageMarker - static_cast<std::int32_t>(index);
  first_.push_back(static_cast<std::uint32_t>(labels_.size()));
  labels_.resize(labels_.size() + components, kNoLabel);
}

void LabelLayer::shift(std::int32_t offset) {
  for (std::int32_t& entry : block_label_) {
    if (entry >= 0) entry += offset;
  }
  for (std::int32_t& label : labels_) {
    if (label >= 0) label += offset;
  }
}

}  // namespace maximal_workspace
