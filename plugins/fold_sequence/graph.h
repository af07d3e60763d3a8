// The machine's states and transitions as Graphviz (dot): one cluster per superstate, one edge
// per row of states.h labelled with its event, guard and reason, its initial children marked.
// `crease-fold-graph` prints it; `dot -Tsvg` draws it. Non-RT.
#pragma once

#include <string>

namespace crease::fold {

struct FoldSpec;

// With a fold, each state's label carries its timeout (s) and follow_via its via count.
[[nodiscard]] std::string graphviz(const FoldSpec* fold = nullptr);

}  // namespace crease::fold
