#include "workspace/block_storage.h"

#include <algorithm>

namespace maximal_workspace {

bool CodeMap::holds(std::uint64_t block, CellCode code) const {
  if (uniform(block)) return uniformCode(block) == code;
  const Page cells = page(block);
  for (int c = 0; c < narrow_.pageSize(); ++c) {
    if (cells[c] == code) return true;
  }
  return false;
}

void CodeMap::addPage(std::uint64_t block, const CellCode* codes) {
  const int cells = narrow_.pageSize();
  if (!wide_pages_ && !std::all_of(codes, codes + cells, fitsNarrow)) widen();
  if (wide_pages_) {
    const std::uint32_t index = wide_.add();
    std::copy(codes, codes + cells, wide_.page(index));
    entry_[block] = index;
    return;
  }
  const std::uint32_t index = narrow_.add();
  std::uint16_t* page = narrow_.page(index);
  for (int c = 0; c < cells; ++c) page[c] = static_cast<std::uint16_t>(codes[c]);
  entry_[block] = index;
}

void CodeMap::setMarker(std::uint64_t block, int cell, CellCode marker) {
  if (wide_pages_) {
    wide_.page(entry_[block])[cell] = marker;
  } else {
    narrow_.page(entry_[block])[cell] = static_cast<std::uint16_t>(marker);
  }
}

// Page indices stay: narrow page i becomes wide page i.
void CodeMap::widen() {
  const int cells = narrow_.pageSize();
  for (std::uint32_t p = 0; p < narrow_.size(); ++p) {
    const std::uint16_t* narrow = narrow_.page(p);
    std::transform(narrow, narrow + cells, wide_.page(wide_.add()), fromNarrow);
  }
  narrow_ = PagePool<std::uint16_t>(cells);
  wide_pages_ = true;
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

void ProofMap::addPage(std::uint64_t block, const std::uint8_t* packed) {
  const std::uint32_t page_index = pages_.add();
  near_pages_.add();
  entry_[block] = page_index;
  std::uint8_t* page = pages_.page(page_index);
  std::uint64_t* near = near_pages_.page(page_index);
  std::fill(near, near + near_pages_.pageSize(), std::uint64_t{0});
  const int cells = pages_.pageSize() / index_bytes_;
  int assembled_cells = 0;
  for (int c = 0; c < cells; ++c) assembled_cells += (packed[static_cast<std::size_t>(c) * width_] & 1) != 0;
  std::uint64_t* assembled = nullptr;
  if (assembled_cells == cells || assembled_cells == 0) {
    assembled_entry_.push_back(assembled_cells == 0 ? kNone : kAll);
  } else {
    assembled_entry_.push_back(assembled_pages_.add());
    assembled = assembled_pages_.page(assembled_entry_.back());
    std::fill(assembled, assembled + assembled_pages_.pageSize(), std::uint64_t{0});
  }
  // Neighbouring cells mostly share their proof: the palette is searched once a run.
  std::uint64_t last_modes = 0;
  std::uint32_t last_index = 0;
  for (int c = 0; c < cells; ++c) {
    CellProof proof = unpack(packed + static_cast<std::size_t>(c) * width_);
    if (!proof.assembly) proof.modes = 0;  // read only with the flag (assembly_modes.cpp)
    if (proof.near_boundary) near[c >> 6] |= std::uint64_t{1} << (c & 63);
    if (proof.assembly && assembled != nullptr) assembled[c >> 6] |= std::uint64_t{1} << (c & 63);
    if (index_bytes_ == 1) {
      page[c] = static_cast<std::uint8_t>(proof.modes);
      continue;
    }
    if (c == 0 || proof.modes != last_modes) {
      last_modes = proof.modes;
      last_index = index(proof.modes);
    }
    page[2 * c] = static_cast<std::uint8_t>(last_index), page[2 * c + 1] = static_cast<std::uint8_t>(last_index >> 8);
  }
}

std::uint32_t ProofMap::index(std::uint64_t modes) {
  const auto found = palette_index_.find(modes);
  if (found != palette_index_.end()) return found->second;
  if (modes == 0 || palette_.size() == (std::size_t{1} << (8 * index_bytes_))) return 0;
  palette_.push_back(modes);
  const std::uint32_t index = static_cast<std::uint32_t>(palette_.size() - 1);
  palette_index_.emplace(modes, index);
  return index;
}

}  // namespace maximal_workspace
