#include "core/config/yaml_reader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>

namespace crease::config {
namespace {

const char* type_name(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Null: return "null";
    case YAML::NodeType::Scalar: return "a scalar";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Map: return "a map";
    case YAML::NodeType::Undefined: break;
  }
  return "nothing";
}

[[noreturn]] void fail(const std::string& file, const YAML::Node& node, const std::string& path,
                       const std::string& reason) {
  throw ConfigError(loc_of(file, node), path, reason);
}

const std::string& require_scalar(const std::string& file, const YAML::Node& node,
                                  const std::string& path, const char* expected) {
  if (!node.IsScalar()) {
    fail(file, node, path, std::string("expected ") + expected + ", got " + type_name(node));
  }
  return node.Scalar();
}

// The case-insensitive edit distance of A and B, or LIMIT when it is LIMIT or more. Two words
// whose lengths differ by LIMIT are that far apart already (a fuzzed key of a thousand bytes
// costs nothing), and a row whose every cell has reached LIMIT ends it (a row's minimum never
// decreases).
std::size_t edit_distance_below(const std::string& a, const std::string& b, std::size_t limit) {
  if ((a.size() > b.size() ? a.size() - b.size() : b.size() - a.size()) >= limit) return limit;
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    std::size_t row_min = cur[0];
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (same ? 0 : 1)});
      row_min = std::min(row_min, cur[j]);
    }
    if (row_min >= limit) return limit;
    std::swap(prev, cur);
  }
  return std::min(prev[b.size()], limit);
}

}  // namespace

SourceLoc loc_of(const std::string& file, const YAML::Node& node) {
  SourceLoc loc{file, 0, 0};
  if (node.IsDefined()) {
    const YAML::Mark m = node.Mark();
    if (!m.is_null()) {
      loc.line = m.line + 1;
      loc.column = m.column + 1;
    }
  }
  return loc;
}

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_d = 3;  // a candidate is only suggested within distance 2
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance_below(word, c, best_d);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  return best;
}

std::string read_string(const std::string& file, const YAML::Node& node, const std::string& path) {
  const std::string& s = require_scalar(file, node, path, "a string");
  if (s.empty()) fail(file, node, path, "must not be empty");
  return s;
}

std::int64_t read_int(const std::string& file, const YAML::Node& node, const std::string& path,
                      std::int64_t min, std::int64_t max) {
  const std::string& s = require_scalar(file, node, path, "an integer");
  std::int64_t v = 0;
  std::istringstream in(s);
  in >> v;
  if (s.empty() || in.fail() || !(in >> std::ws).eof()) {
    fail(file, node, path, "expected an integer, got '" + s + "'");
  }
  if (v < min || v > max) {
    fail(file, node, path,
         "must be in [" + std::to_string(min) + ", " + std::to_string(max) + "], got " + s);
  }
  return v;
}

double read_number(const std::string& file, const YAML::Node& node, const std::string& path,
                   double min, double max, bool min_exclusive) {
  const std::string& s = require_scalar(file, node, path, "a number");
  double v = 0;
  std::istringstream in(s);
  in >> v;
  if (s.empty() || in.fail() || !(in >> std::ws).eof() || !std::isfinite(v)) {
    fail(file, node, path, "expected a finite number, got '" + s + "'");
  }
  const bool below = min_exclusive ? !(v > min) : v < min;
  if (below || v > max) {
    std::ostringstream msg;
    msg << "must be in " << (min_exclusive ? "(" : "[") << min << ", " << max << "], got " << s;
    fail(file, node, path, msg.str());
  }
  return v;
}

bool read_bool(const std::string& file, const YAML::Node& node, const std::string& path) {
  const std::string& s = require_scalar(file, node, path, "true or false");
  if (s == "true" || s == "True" || s == "TRUE") return true;
  if (s == "false" || s == "False" || s == "FALSE") return false;
  fail(file, node, path, "expected true or false, got '" + s + "'");
}

MapReader::MapReader(std::string file, const YAML::Node& node, std::string path,
                     std::initializer_list<const char*> allowed)
    : file_(std::move(file)), node_(node), path_(std::move(path)) {
  if (!node_.IsMap()) {
    fail(file_, node_, path_.empty() ? "(document)" : path_,
         std::string("expected a map, got ") + type_name(node_));
  }
  const std::vector<std::string> allowed_keys(allowed.begin(), allowed.end());
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const YAML::Node key = it->first;
    if (!key.IsScalar()) fail(file_, key, path_of("?"), "keys must be plain strings");
    const std::string& k = key.Scalar();
    if (std::find(allowed_keys.begin(), allowed_keys.end(), k) == allowed_keys.end()) {
      std::string reason = "unknown key '" + k + "'";
      const std::string guess = did_you_mean(k, allowed_keys);
      if (!guess.empty()) reason += " (did you mean '" + guess + "'?)";
      fail(file_, key, path_of(k), reason);
    }
    for (const auto& e : entries_) {
      if (e.first == k) fail(file_, key, path_of(k), "duplicate key '" + k + "'");
    }
    entries_.emplace_back(k, it->second);
  }
}

bool MapReader::has(const std::string& key) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const auto& e) { return e.first == key; });
}

YAML::Node MapReader::get(const std::string& key) const {
  for (const auto& e : entries_) {
    if (e.first == key) return e.second;
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

YAML::Node MapReader::require(const std::string& key) const {
  for (const auto& e : entries_) {
    if (e.first == key) return e.second;
  }
  fail(file_, node_, path_of(key), "required key is missing");
}

std::string MapReader::path_of(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

SourceLoc MapReader::loc() const { return loc_of(file_, node_); }

}  // namespace crease::config
