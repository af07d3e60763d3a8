// crease-bench SUBCOMMAND [ARGS]: benchmarks that print Crease's figure beside the
// alternative's, measured in the same run.
#include <cstdio>
#include <cstring>

#include "bench_registry.h"

namespace crease::bench {
std::map<std::string, BenchEntry>& registry() {
  static std::map<std::string, BenchEntry> r;
  return r;
}
}  // namespace crease::bench

int main(int argc, char** argv) {
  auto& reg = crease::bench::registry();
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    std::printf("usage: crease-bench SUBCOMMAND [ARGS]\n\nsubcommands:\n");
    for (const auto& [name, e] : reg) std::printf("  %-10s %s\n", name.c_str(), e.help.c_str());
    return argc < 2 ? 2 : 0;
  }
  auto it = reg.find(argv[1]);
  if (it == reg.end()) {
    std::fprintf(stderr, "crease-bench: unknown subcommand '%s' (see crease-bench --help)\n", argv[1]);
    return 2;
  }
  return it->second.fn(argc - 1, argv + 1);
}
