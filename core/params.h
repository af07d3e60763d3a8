// A plugin's parameters: a YAML map from the configuration, with typed, checked access.
//
// Every failed lookup throws ConfigError naming the file, line, column and key path, e.g.
//   sim.yaml:42:9: plugins[3].params.gain: expected a number, got 'fast'
// Keys a plugin never reads are reported by unused_keys() so the host can refuse typos.
// Non-RT only.
#pragma once

#include <yaml-cpp/yaml.h>

#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/errors.h"

namespace crease {

// Shortest readable form of a number for messages ("0.5", "100", "1e-06").
std::string format_number(double v);

class Params {
 public:
  Params();  // an empty map, for plugins configured without parameters
  // `node` must be a map or null. `file` and `path` prefix every message.
  Params(YAML::Node node, std::string file, std::string path);

  [[nodiscard]] bool has(std::string_view key) const;

  // Required value; throws ConfigError when absent or of the wrong type.
  template <class T>
  [[nodiscard]] T get(std::string_view key) const {
    const YAML::Node n = lookup(key, true);
    return convert<T>(n, key);
  }
  // Optional value with a default.
  template <class T>
  [[nodiscard]] T get(std::string_view key, T fallback) const {
    const YAML::Node n = lookup(key, false);
    if (!n) return fallback;
    return convert<T>(n, key);
  }
  // Optional number checked against [lo, hi].
  template <class T>
  [[nodiscard]] T get_in_range(std::string_view key, T fallback, T lo, T hi) const {
    const T v = get<T>(key, fallback);
    if (!(v >= lo && v <= hi)) {
      fail(key, "must be in [" + format_number(lo) + ", " + format_number(hi) + "], got " + format_number(v));
    }
    return v;
  }

  // A path: the string value (or the fallback), relative paths resolved against the folder of
  // the file the parameters came from (the configuration's folder; the working directory for
  // parameters of a control request).
  [[nodiscard]] std::string get_path(std::string_view key, const std::string& fallback) const;
  [[nodiscard]] std::string get_path(std::string_view key) const;  // required
  // The same resolution for a path the plugin read itself (an item of a list).
  [[nodiscard]] std::string resolve_path(const std::string& value) const;

  // A nested map (throws when present but not a map; empty when absent).
  [[nodiscard]] Params child(std::string_view key) const;
  // A list of maps, each element a Params named `key[i]` (throws when present but not a list of
  // maps; empty when absent). unused_keys() looks inside the elements.
  [[nodiscard]] std::vector<Params> list(std::string_view key) const;
  // The raw node, for lists and structures a plugin parses itself (use where() in messages).
  [[nodiscard]] YAML::Node raw(std::string_view key) const;

  // "file:line:col: path.key" for messages about `key` (or about the map itself if empty).
  [[nodiscard]] std::string where(std::string_view key = {}) const;
  [[noreturn]] void fail(std::string_view key, const std::string& reason) const;

  // Keys present in this map (and its children) that were never read.
  [[nodiscard]] std::vector<std::string> unused_keys() const;
  [[nodiscard]] const std::string& file() const noexcept { return file_; }

 private:
  YAML::Node lookup(std::string_view key, bool required) const;
  template <class T>
  T convert(const YAML::Node& n, std::string_view key) const {
    if (!n.IsScalar()) fail(key, std::string("expected ") + type_name<T>() + ", got a " + (n.IsMap() ? "map" : "list"));
    try {
      return n.as<T>();
    } catch (const YAML::Exception&) {
      fail(key, std::string("expected ") + type_name<T>() + ", got '" + n.Scalar() + "'");
    }
  }
  template <class T>
  static constexpr const char* type_name() {
    if constexpr (std::is_same_v<T, bool>) return "true or false";
    else if constexpr (std::is_integral_v<T>) return "an integer";
    else if constexpr (std::is_floating_point_v<T>) return "a number";
    else return "a string";
  }

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::shared_ptr<std::set<std::string>> used_;  // full key paths read, shared with children
};

}  // namespace crease
