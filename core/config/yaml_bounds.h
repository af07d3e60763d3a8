// Bounds on a configuration's YAML before it becomes nodes: its size, and its node count with
// every alias expanded (an alias repeats its anchored node: nested aliases multiply, so a few
// lines can stand for 10^10 nodes that any walk of the tree would visit).
//
//   YAML::Node doc = crease::config::load_bounded_yaml(text, "sim.yaml", {});
//
// Every refusal throws ConfigError "FILE:LINE:COLUMN: KEY.PATH: reason", pointing at the byte
// (size) or the node (count, alias cycle) where the limit is crossed. Cost: one extra event
// pass over the text, linear in its size whatever its aliases, where the count can fail.
#pragma once

#include <cstddef>
#include <string>

#include <yaml-cpp/yaml.h>

namespace crease::config {

struct YamlBounds {
  std::size_t max_bytes = std::size_t{1} << 20;  // the text's size in bytes
  std::size_t max_nodes = 100'000;               // scalars, nulls, lists and maps, aliases expanded
};

// Throws ConfigError at the first byte past BOUNDS.max_bytes of TEXT (the line and column of
// that byte in FILE) when TEXT is larger.
void check_yaml_size(const std::string& text, const std::string& file, const YamlBounds& bounds);

// The first document of TEXT as nodes (marks kept), after check_yaml_size and a count of its
// nodes with aliases expanded: more than BOUNDS.max_nodes, or an alias inside the node it
// names (a cycle), throws ConfigError naming the node where it happens and its key path.
// YAML syntax errors throw ConfigError with key path "(syntax)". The count is a second parse
// of the text, made only where it can fail (node_count_cannot_pass).
[[nodiscard]] YAML::Node load_bounded_yaml(const std::string& text, const std::string& file,
                                           const YamlBounds& bounds);

// The counting pass alone: the nodes of TEXT's first document with aliases expanded; throws
// as load_bounded_yaml does past the limit, at a cycle and at a syntax error.
[[nodiscard]] std::size_t count_yaml_nodes(const std::string& text, const std::string& file,
                                           const YamlBounds& bounds);

// A text without aliases (no '*' anywhere) has at most kMaxNodesPerByte nodes per byte, plus
// one: a node needs a token of at least one byte, and one byte (':', '?', '-') opens at most a
// map with an empty key and an empty value (tested on random texts, yaml_bounds_test). True
// when TEXT is too short to pass BOUNDS.max_nodes that way: its count need not be made (the
// default limit: texts up to 24,999 bytes, every configuration of this repository).
inline constexpr std::size_t kMaxNodesPerByte = 4;  // 3 seen at most, one to spare
[[nodiscard]] bool node_count_cannot_pass(const std::string& text, const YamlBounds& bounds) noexcept;

}  // namespace crease::config
