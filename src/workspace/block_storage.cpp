#include "workspace/block_storage.h"

#include <algorithm>

namespace maximal_workspace {

CellCode* CodeMap::addPage(std::uint64_t block) {
  const std::uint32_t index = pages_.add();
  entry_[block] = index;
  return pages_.page(index);
}

void LabelLayer::addPage(std::uint64_t block, const std::uint16_t* local, std::uint32_t components) {
  block_label_[block] = kPageMarker - static_cast<std::int32_t>(slot_.size());
  first_.push_back(static_cast<std::uint32_t>(labels_.size()));
  labels_.resize(labels_.size() + components, kNoLabel);
  if (components < kNarrowNone) {
    const std::uint32_t index = narrow_.add();
    slot_.push_back(index << 1);
    std::uint8_t* page = narrow_.page(index);
    for (int c = 0; c < narrow_.pageSize(); ++c) page[c] = local[c] == kNoLocal ? kNarrowNone : static_cast<std::uint8_t>(local[c]);
  } else {
    const std::uint32_t index = wide_.add();
    slot_.push_back(index << 1 | 1);
    std::copy(local, local + wide_.pageSize(), wide_.page(index));
  }
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
