// Small helpers shared by the benchmarks: argument parsing and percentile printing.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>

#include "core/plugin_host.h"

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

// A plugin instance for a benchmark's host; `out` is remapped to "<name>_out" unless `ports` says.
inline InstanceSpec instance(const std::string& name, const std::string& library, const std::string& loop,
                             const std::string& yaml = "{}", int order = 0,
                             std::map<std::string, std::string> ports = {}) {
  InstanceSpec s;
  s.name = name;
  s.library = library;
  s.loop = loop;
  s.order = order;
  s.params = Params(YAML::Load(yaml), "bench", name);
  s.ports = ports.empty() ? std::map<std::string, std::string>{{"out", name + "_out"}} : std::move(ports);
  return s;
}

}  // namespace crease::bench
