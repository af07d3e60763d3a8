// Small helpers shared by the benchmarks: argument parsing and percentile printing.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

namespace crease::bench {

// "--name VALUE" from argv, or `fallback`.
inline double arg_double(int argc, char** argv, const char* name, double fallback) {
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], name) == 0) return std::atof(argv[i + 1]);
  }
  return fallback;
}

inline bool has_flag(int argc, char** argv, const char* name) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], name) == 0) return true;
  }
  return false;
}

inline double ratio(double ours, double theirs) { return theirs > 0 ? ours / theirs : 0.0; }

}  // namespace crease::bench
