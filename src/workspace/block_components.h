#pragma once
// Connected components (faces shared) over the block structure, without expanding it: a
// block whose cells share one key is one node of the search, and only the cells of the
// other blocks are nodes of their own. The key of a cell is a function of its code (a
// table); cells of key 0 belong to no component. Internal to the engine.

#include <cstdint>
#include <vector>

#include "maximal_workspace/workspace/cancellation.h"
#include "workspace/block_storage.h"

namespace maximal_workspace {

struct Component {
  std::uint8_t key = 0;
  std::uint64_t cells = 0;
  std::uint64_t seed_block = 0;  // first node in block order
  int seed_cell = 0;
};

// key_of_code: the key of every code. Fills `layer` (which must be empty)
// with the component of every cell; components are numbered from 0 in block order of their
// first node; cells do not join across the cuts of `cut_mode` (-1: gaps alone; a cut's
// blocks must have pages of codes).
// `cancelled` is asked every kBlocksBetweenChecks blocks of each pass.
std::vector<Component> labelComponents(const BlockLayout& layout, const CodeMap& codes,
                                       const CodeTable<std::uint8_t>& key_of_code, const FaceCuts& cuts,
                                       int cut_mode, LabelLayer* layer, const CancelCheck& cancelled = {});

}  // namespace maximal_workspace
