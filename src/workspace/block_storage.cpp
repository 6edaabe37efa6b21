#include "workspace/block_storage.h"

#include <algorithm>

namespace maximal_workspace {

CellCode* CodeMap::addPage(std::uint64_t block) {
  const std::uint32_t index = pages_.add();
  entry_[block] = index;
  return pages_.page(index);
}

std::int32_t* LabelLayer::addPage(std::uint64_t block) {
  const std::uint32_t index = pages_.add();
  block_label_[block] = kPageMarker - static_cast<std::int32_t>(index);
  std::int32_t* page = pages_.page(index);
  std::fill_n(page, pages_.pageSize(), kNoLabel);
  return page;
}

void LabelLayer::shift(std::int32_t offset) {
  for (std::int32_t& entry : block_label_) {
    if (entry >= 0) entry += offset;
  }
  for (std::uint32_t p = 0; p < pages_.size(); ++p) {
    std::int32_t* page = pages_.page(p);
    for (int c = 0; c < pages_.pageSize(); ++c) {
      if (page[c] >= 0) page[c] += offset;
    }
  }
}

}  // namespace maximal_workspace
