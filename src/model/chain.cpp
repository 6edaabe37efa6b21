#include "maximal_workspace/model/chain.h"

namespace maximal_workspace {

char branchLetter(Branch branch) { return branch == Branch::Positive ? 'p' : 'n'; }

const char* inputUnit(InputKind kind) { return kind == InputKind::Prismatic ? "m" : "rad"; }

}  // namespace maximal_workspace
