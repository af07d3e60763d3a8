// crease-bench subcommand registry. Each bench_<name>.cpp registers itself:
//   static int run_sheet(int argc, char** argv);
//   CREASE_BENCH(sheet, "time and accuracy of the sheet model against Bullet and ODE", run_sheet);
// A bench prints our figure next to the alternative's from the same run and ends with one
// line of key=value pairs: "<name>: key=value key=value ...".
#pragma once

#include <map>
#include <string>

namespace crease::bench {

using BenchFn = int (*)(int argc, char** argv);  // argv[0] is the subcommand name

struct BenchEntry {
  std::string help;
  BenchFn fn;
};

std::map<std::string, BenchEntry>& registry();

struct Registrar {
  Registrar(const char* name, const char* help, BenchFn fn) { registry()[name] = {help, fn}; }
};

}  // namespace crease::bench

#define CREASE_BENCH(name, help, fn) \
  static const ::crease::bench::Registrar crease_bench_registrar_##name(#name, help, fn)
