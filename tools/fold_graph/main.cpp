// crease-fold-graph: prints the folding sequence's states and transitions (plugins/fold_sequence)
// as Graphviz; with a sequence file, each state's timeout and the bend's via points too.
//   crease-fold-graph [config/folds/half.yaml] | dot -Tsvg > fold.svg
// A malformed sequence file: its FILE:LINE:COLUMN: KEY: reason on stderr, exit status 2.
#include <cstdio>
#include <exception>
#include <optional>
#include <string>

#include "core/errors.h"
#include "plugins/fold_sequence/fold_spec.h"
#include "plugins/fold_sequence/graph.h"

int main(int argc, char** argv) {
  if (argc > 2 || (argc == 2 && (std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help"))) {
    std::fprintf(stderr, "usage: crease-fold-graph [SEQUENCE_FILE.yaml]   (Graphviz dot on stdout)\n");
    return argc > 2 ? 2 : 0;
  }
  try {
    std::optional<crease::fold::FoldSpec> fold;
    if (argc == 2) fold = crease::fold::load_fold_file(argv[1]);
    const std::string dot = crease::fold::graphviz(fold ? &*fold : nullptr);
    std::fwrite(dot.data(), 1, dot.size(), stdout);
    return 0;
  } catch (const crease::ConfigError& e) {
    std::fprintf(stderr, "crease-fold-graph: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crease-fold-graph: %s\n", e.what());
    return 1;
  }
}
