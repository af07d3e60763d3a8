#include "plugins/sheet_score/recording_score.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/errors.h"

namespace crease::sheet_score {
namespace {

[[noreturn]] void fail(const std::string& path, int line, const std::string& why) {
  throw crease::Error(path + ":" + std::to_string(line) + ": " + why);
}

double key_of(const RecordedSheet& s, Pairing p) { return p == Pairing::stamp ? double(s.stamp_ns) * 1e-9 : s.t_s; }

}  // namespace

std::vector<RecordedSheet> read_recording(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw crease::Error("cannot read '" + path + "'");
  std::vector<RecordedSheet> out;
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    if (text.empty()) continue;
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
      fail(path, line, std::string("not JSON: ") + e.what());
    }
    if (!j.is_object()) fail(path, line, "not a JSON object");
    RecordedSheet s;
    try {
      s.t_s = j.at("t").get<double>();
      if (j.contains("stamp_ns")) {
        s.stamp_ns = j.at("stamp_ns").get<std::int64_t>();
        s.has_stamp = true;
      }
      s.frame = j.at("frame").get<std::uint64_t>();
      const auto& g = j.at("grid");
      if (!g.is_array() || g.size() != 2) fail(path, line, "grid: must be [W, H]");
      s.nodes_u = g[0].get<int>();
      s.nodes_v = g[1].get<int>();
      const auto& n = j.at("nodes");
      if (s.nodes_u < 1 || s.nodes_v < 1 || !n.is_array() ||
          n.size() != static_cast<std::size_t>(s.nodes_u) * static_cast<std::size_t>(s.nodes_v))
        fail(path, line, "nodes: must hold grid W x H nodes");
      s.nodes.reserve(n.size());
      for (const auto& p : n) {
        if (!p.is_array() || p.size() != 3) fail(path, line, "nodes: each must be [x, y, z]");
        s.nodes.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
        for (double c : s.nodes.back())
          if (!std::isfinite(c)) fail(path, line, "nodes: not finite");
      }
    } catch (const nlohmann::json::exception& e) {
      fail(path, line, std::string("missing or mistyped field: ") + e.what());
    }
    if (!std::isfinite(s.t_s)) fail(path, line, "t: not finite");
    if (!out.empty() && (s.t_s < out.back().t_s || (s.has_stamp && out.back().has_stamp && s.stamp_ns < out.back().stamp_ns)))
      fail(path, line, "time goes back");
    out.push_back(std::move(s));
  }
  if (out.empty()) throw crease::Error(path + ": no recorded frame");
  return out;
}

Pairing default_pairing(const std::vector<RecordedSheet>& model, const std::vector<RecordedSheet>& truth) {
  auto stamped = [](const std::vector<RecordedSheet>& v) {
    return std::all_of(v.begin(), v.end(), [](const RecordedSheet& s) { return s.has_stamp; });
  };
  return stamped(model) && stamped(truth) ? Pairing::stamp : Pairing::time;
}

RecordingScore score_recording(const std::vector<RecordedSheet>& model, const std::vector<RecordedSheet>& truth,
                               Pairing pairing, double shift_s) {
  RecordingScore r;
  if (truth.empty()) throw crease::Error("the truth has no frame");
  double sum = 0;
  for (const RecordedSheet& m : model) {
    const double k = key_of(m, pairing) + shift_s;
    auto hi = std::lower_bound(truth.begin(), truth.end(), k,
                               [pairing](const RecordedSheet& s, double key) { return key_of(s, pairing) < key; });
    if (hi == truth.end() || (hi == truth.begin() && key_of(*hi, pairing) > k)) {
      ++r.skipped;
      continue;
    }
    const RecordedSheet& b = *hi;
    const RecordedSheet& a = hi == truth.begin() ? b : *std::prev(hi);
    if (a.nodes_u != m.nodes_u || a.nodes_v != m.nodes_v || b.nodes_u != m.nodes_u || b.nodes_v != m.nodes_v)
      throw crease::Error("model frame " + std::to_string(m.frame) + " has a " + std::to_string(m.nodes_u) + " x " +
                          std::to_string(m.nodes_v) + " grid, the truth " + std::to_string(b.nodes_u) + " x " +
                          std::to_string(b.nodes_v));
    const double ka = key_of(a, pairing), kb = key_of(b, pairing);
    const double f = kb > ka ? std::clamp((k - ka) / (kb - ka), 0.0, 1.0) : 1.0;
    double err = 0;
    for (std::size_t n = 0; n < m.nodes.size(); ++n) {
      double d2 = 0;
      for (int c = 0; c < 3; ++c) {
        const double t = a.nodes[n][c] + f * (b.nodes[n][c] - a.nodes[n][c]);
        d2 += (m.nodes[n][c] - t) * (m.nodes[n][c] - t);
      }
      err += std::sqrt(d2);
    }
    err /= double(m.nodes.size());
    r.frames.push_back({m.t_s, err});
    sum += err;
    if (err > r.worst_mm) {
      r.worst_mm = err;
      r.worst_t_s = m.t_s;
    }
    r.end_mm = err;
  }
  if (r.frames.empty()) throw crease::Error("no model frame lies within the truth's time span");
  r.mean_mm = sum / double(r.frames.size());
  return r;
}

}  // namespace crease::sheet_score
