// Strict, mark-aware reading of YAML maps and scalars for configuration files.
// Every failure throws ConfigError "FILE:LINE:COLUMN: KEY.PATH: reason".
#pragma once

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "core/config/daemon_config.h"

namespace crease::config {

// 1-based location of NODE in FILE (0:0 when the node has no mark).
[[nodiscard]] SourceLoc loc_of(const std::string& file, const YAML::Node& node);

// Closest candidate within edit distance 2 (case-insensitive), or "" when none.
[[nodiscard]] std::string did_you_mean(const std::string& word,
                                       const std::vector<std::string>& candidates);

// Typed scalar reads; PATH names the value in messages.
[[nodiscard]] std::string read_string(const std::string& file, const YAML::Node& node,
                                      const std::string& path);
[[nodiscard]] std::int64_t read_int(const std::string& file, const YAML::Node& node,
                                    const std::string& path, std::int64_t min, std::int64_t max);
// Finite number in [min, max]; MIN_EXCLUSIVE makes the lower bound open.
[[nodiscard]] double read_number(const std::string& file, const YAML::Node& node,
                                 const std::string& path, double min, double max,
                                 bool min_exclusive);
[[nodiscard]] bool read_bool(const std::string& file, const YAML::Node& node,
                             const std::string& path);

// A YAML map whose keys are checked against an allowed set: unknown and duplicate keys
// throw at construction.
class MapReader {
 public:
  MapReader(std::string file, const YAML::Node& node, std::string path,
            std::initializer_list<const char*> allowed);

  [[nodiscard]] bool has(const std::string& key) const;
  // The value, or an undefined node when absent.
  [[nodiscard]] YAML::Node get(const std::string& key) const;
  // The value; throws "required key is missing" at the map when absent.
  [[nodiscard]] YAML::Node require(const std::string& key) const;
  // "path.key" (or "key" at the top level).
  [[nodiscard]] std::string path_of(const std::string& key) const;
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  [[nodiscard]] SourceLoc loc() const;

 private:
  std::string file_;
  YAML::Node node_;
  std::string path_;
  std::vector<std::pair<std::string, YAML::Node>> entries_;  // key -> value, file order
};

}  // namespace crease::config
