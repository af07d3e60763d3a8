#include "tools/creasectl/human_format.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace crease::ctl {
namespace {

std::string scalar(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_null()) return "-";
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_number_float()) {
    // Up to 3 decimals, trailing zeros dropped: 1.449075 -> "1.449", 1000.0 -> "1000".
    const double d = v.get<double>();
    char buf[64];
    const double a = std::fabs(d);
    if (a != 0 && (a >= 1e12 || a < 1e-3)) {
      std::snprintf(buf, sizeof(buf), "%.6g", d);
      return buf;
    }
    std::snprintf(buf, sizeof(buf), "%.3f", d);
    std::string s = buf;
    while (!s.empty() && s.back() == '0') s.pop_back();
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s == "-0" ? "0" : s;
  }
  return v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

bool is_table(const nlohmann::json& v) {
  return v.is_array() && !v.empty() &&
         std::all_of(v.begin(), v.end(), [](const nlohmann::json& e) { return e.is_object(); });
}

bool is_flat(const nlohmann::json& v) { return !v.is_object() && !v.is_array(); }

void table(std::string& out, const nlohmann::json& rows, const std::string& indent) {
  std::vector<std::string> cols;
  for (const auto& row : rows) {
    for (auto it = row.begin(); it != row.end(); ++it) {
      if (std::find(cols.begin(), cols.end(), it.key()) == cols.end()) cols.push_back(it.key());
    }
  }
  // "name" first when present: it is what people scan for.
  const auto name = std::find(cols.begin(), cols.end(), "name");
  if (name != cols.end()) std::rotate(cols.begin(), name, name + 1);
  std::vector<std::vector<std::string>> cells;
  std::vector<std::size_t> width(cols.size());
  for (std::size_t c = 0; c < cols.size(); ++c) width[c] = cols[c].size();
  for (const auto& row : rows) {
    std::vector<std::string> line;
    for (std::size_t c = 0; c < cols.size(); ++c) {
      const auto it = row.find(cols[c]);
      std::string cell = it == row.end() ? "" : (is_flat(*it) ? scalar(*it) : it->dump());
      width[c] = std::max(width[c], cell.size());
      line.push_back(std::move(cell));
    }
    cells.push_back(std::move(line));
  }
  auto emit = [&](const std::vector<std::string>& line) {
    std::string s = indent;
    for (std::size_t c = 0; c < line.size(); ++c) {
      s += line[c];
      if (c + 1 < line.size()) s += std::string(width[c] - line[c].size() + 2, ' ');
    }
    while (!s.empty() && s.back() == ' ') s.pop_back();
    out += s + "\n";
  };
  emit(cols);
  for (const auto& line : cells) emit(line);
}

void format_into(std::string& out, const nlohmann::json& v, const std::string& indent) {
  if (v.is_object()) {
    for (auto it = v.begin(); it != v.end(); ++it) {
      if (is_flat(*it)) {
        out += indent + it.key() + ": " + scalar(*it) + "\n";
      } else if (it->is_array() && std::all_of(it->begin(), it->end(), is_flat)) {
        std::string line;
        for (const auto& e : *it) line += (line.empty() ? "" : ", ") + scalar(e);
        out += indent + it.key() + ": " + (line.empty() ? "(none)" : line) + "\n";
      } else {
        out += indent + it.key() + ":\n";
        format_into(out, *it, indent + "  ");
      }
    }
  } else if (is_table(v)) {
    table(out, v, indent);
  } else if (v.is_array()) {
    for (const auto& e : v) {
      if (is_flat(e)) {
        out += indent + "- " + scalar(e) + "\n";
      } else {
        out += indent + "-\n";
        format_into(out, e, indent + "  ");
      }
    }
  } else {
    out += indent + scalar(v) + "\n";
  }
}

}  // namespace

std::string format_human(const nlohmann::json& value) {
  std::string out;
  format_into(out, value, "");
  return out;
}

nlohmann::json parse_cli_value(const std::string& text) {
  nlohmann::json v = nlohmann::json::parse(text, nullptr, false);
  if (v.is_discarded()) return text;
  return v;
}

}  // namespace crease::ctl
