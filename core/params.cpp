#include "core/params.h"

#include <cstdio>
#include <filesystem>

namespace crease {

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.10g", v);
  return buf;
}

namespace {
std::string mark_text(const YAML::Node& n) {
  if (!n) return "";
  const YAML::Mark m = n.Mark();
  if (m.line < 0) return "";
  return std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1) + ":";
}
}  // namespace

Params::Params() : node_(YAML::NodeType::Map), used_(std::make_shared<std::set<std::string>>()) {}

Params::Params(YAML::Node node, std::string file, std::string path)
    : node_(node ? node : YAML::Node(YAML::NodeType::Map)),
      file_(std::move(file)),
      path_(std::move(path)),
      used_(std::make_shared<std::set<std::string>>()) {
  if (node_.IsNull()) node_ = YAML::Node(YAML::NodeType::Map);
  if (!node_.IsMap()) fail({}, "expected a map of parameters");
}

bool Params::has(std::string_view key) const { return static_cast<bool>(node_[std::string(key)]); }

std::string Params::where(std::string_view key) const {
  YAML::Node n = key.empty() ? node_ : node_[std::string(key)];
  std::string loc = file_.empty() ? std::string() : file_ + ":";
  std::string m = mark_text(n ? n : node_);
  if (!m.empty()) loc += m;
  std::string p = path_;
  if (!key.empty()) p += (p.empty() ? "" : ".") + std::string(key);
  return loc.empty() ? p : loc + " " + p;
}

void Params::fail(std::string_view key, const std::string& reason) const {
  throw ConfigError(where(key) + ": " + reason);
}

YAML::Node Params::lookup(std::string_view key, bool required) const {
  const std::string k(key);
  YAML::Node n = node_[k];
  used_->insert(path_ + "." + k);
  if (!n && required) fail(key, "required parameter is missing");
  if (n && n.IsNull() && required) fail(key, "required parameter has no value");
  if (n && n.IsNull()) return YAML::Node();
  return n;
}

std::string Params::resolve_path(const std::string& value) const {
  const std::filesystem::path v(value);
  if (v.is_absolute()) return value;
  return (std::filesystem::path(file_).parent_path() / v).string();
}

std::string Params::get_path(std::string_view key, const std::string& fallback) const {
  return resolve_path(get<std::string>(key, fallback));
}

std::string Params::get_path(std::string_view key) const { return resolve_path(get<std::string>(key)); }

Params Params::child(std::string_view key) const {
  const YAML::Node n = lookup(key, false);
  used_->insert("child:" + path_ + "." + std::string(key));  // unused_keys() looks inside
  if (!n) {
    Params p(YAML::Node(YAML::NodeType::Map), file_, path_ + "." + std::string(key));
    p.used_ = used_;
    return p;
  }
  if (!n.IsMap()) fail(key, "expected a map");
  Params p(n, file_, path_ + "." + std::string(key));
  p.used_ = used_;
  return p;
}

std::vector<Params> Params::list(std::string_view key) const {
  const YAML::Node n = lookup(key, false);
  used_->insert("list:" + path_ + "." + std::string(key));  // unused_keys() looks inside
  std::vector<Params> out;
  if (!n) return out;
  if (!n.IsSequence()) fail(key, "expected a list of maps");
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string path = path_ + "." + std::string(key) + "[" + std::to_string(i) + "]";
    if (!n[i].IsMap()) {
      Params at(YAML::Node(YAML::NodeType::Map), file_, path);
      at.node_ = n[i];
      at.fail({}, "expected a map");
    }
    Params p(n[i], file_, path);
    p.used_ = used_;
    out.push_back(std::move(p));
  }
  return out;
}

YAML::Node Params::raw(std::string_view key) const { return lookup(key, false); }

std::vector<std::string> Params::unused_keys() const {
  std::vector<std::string> out;
  for (const auto& kv : node_) {
    const std::string k = kv.first.as<std::string>();
    const std::string full = path_ + "." + k;
    if (!used_->count(full)) {
      out.push_back(where(k));
    } else if (kv.second.IsMap()) {
      // A map opened with child(): its keys must be read too. (Maps read with raw() are the
      // plugin's to check.)
      if (used_->count("child:" + full)) {
        Params c(kv.second, file_, full);
        c.used_ = used_;
        for (auto& s : c.unused_keys()) out.push_back(std::move(s));
      }
    } else if (kv.second.IsSequence() && used_->count("list:" + full)) {
      // A list read with list(): the keys of its maps must be read too.
      for (std::size_t i = 0; i < kv.second.size(); ++i) {
        if (!kv.second[i].IsMap()) continue;
        Params c(kv.second[i], file_, full + "[" + std::to_string(i) + "]");
        c.used_ = used_;
        for (auto& s : c.unused_keys()) out.push_back(std::move(s));
      }
    }
  }
  return out;
}

}  // namespace crease
