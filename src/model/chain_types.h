#pragma once
// The leg types a robot file may name. Adding a type (UPS, RPR, ...) means one new chain
// file and one entry in chain_types.cpp.

#include <string>
#include <vector>

#include "maximal_workspace/model/chain.h"
#include "model/field_reader.h"

namespace maximal_workspace {

struct ChainType {
  const char* name;
  // Fields of this type beyond the common ones (name, type, input, rod_length, platform_node).
  std::vector<const char*> fields;
  ChainPtr (*fromFields)(const FieldReader& fields, ChainCommon common);
};

const std::vector<ChainType>& chainTypes();
// Null when no type has this name.
const ChainType* findChainType(const std::string& name);

}  // namespace maximal_workspace
