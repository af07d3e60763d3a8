// The Graphviz dump: a cluster per superstate, a node per leaf, an edge per row.
#include "plugins/fold_sequence/graph.h"

#include <doctest/doctest.h>

#include <string>

#include "plugins/fold_sequence/fold_spec.h"
#include "plugins/fold_sequence/states.h"

using namespace crease::fold;

namespace {
int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (auto at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}
}  // namespace

TEST_CASE("every state and row is in the graph") {
  const FoldSpec f = load_fold_file(std::string(CREASE_SOURCE_DIR) + "/config/folds/half.yaml");
  const std::string g = graphviz(&f);
  CHECK(g.rfind("digraph fold_sequence {", 0) == 0);
  int leaves = 0, supers = 0;
  for (int i = 1; i < kStateCount; ++i) (is_leaf(static_cast<S>(i)) ? leaves : supers)++;
  CHECK(count(g, "subgraph cluster_") == supers);
  CHECK(count(g, "[style=dashed]") == supers);  // the initial children
  const RowSpan rows = all_rows();
  CHECK(count(g, " -> ") == static_cast<int>(rows.end - rows.begin) + supers);
  CHECK(g.find("follow_via[0..7]") != std::string::npos);
  CHECK(g.find("s_fold_anchor -> s_abort_anchor [label=\"fault\", ltail=cluster_s_fold, lhead=cluster_s_abort, color=red]") !=
        std::string::npos);
  CHECK(g.find("pinching arm reached [more via]") != std::string::npos);
  CHECK(count(graphviz(), "\\n") == 0);  // without a fold: no timeouts
}
