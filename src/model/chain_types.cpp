#include "model/chain_types.h"

#include "maximal_workspace/model/pss_chain.h"
#include "maximal_workspace/model/rss_chain.h"

namespace maximal_workspace {

const std::vector<ChainType>& chainTypes() {
  static const std::vector<ChainType> types = {
      {PssChain::kType, {"fixed_node", "direction"}, &PssChain::fromFields},
      {RssChain::kType, {"fixed_node", "axis", "crank_length", "crank_zero"}, &RssChain::fromFields},
  };
  return types;
}

const ChainType* findChainType(const std::string& name) {
  for (const ChainType& type : chainTypes()) {
    if (name == type.name) return &type;
  }
  return nullptr;
}

}  // namespace maximal_workspace
