#include "tools/trials/trial_report.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string_view>

#include "core/report/render.h"
#include "tools/trials/trial_table.h"

namespace crease::trials {
namespace {

// The plot's geometry (SVG px): the states' band along the top, the lines' area below it.
constexpr double kW = 1100, kH = 320, kL = 60, kR = 64;
constexpr double kBandTop = 6, kBandH = 22, kPlotTop = 40, kPlotBottom = kH - 42;
constexpr const char* kForceColour[2] = {"#d62728", "#1f77b4"};  // right, left hand
constexpr const char* kStretchColour = "#2ca02c";

constexpr const char* kStyle = R"(
body{font-family:sans-serif;margin:24px;color:#222;background:#fff}
h1{font-size:22px}h2{font-size:18px;margin-top:28px;border-bottom:1px solid #ccc}h3{font-size:15px}
table{border-collapse:collapse;margin:8px 0;font-size:13px}
td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}th{background:#eef}td.l,th.l{text-align:left}
.yes{color:#070;font-weight:bold}.no{color:#a00}.none,.draws{color:#666;font-size:13px}
svg{background:#fafafa;border:1px solid #ddd}
svg text{font-family:sans-serif;font-size:11px;fill:#333}.measured-r,.measured-l{stroke-dasharray:4 3}svg text.band{pointer-events:none}
)";

// Text for HTML (element content and attribute values alike).
std::string esc(std::string_view s) { return report::html_escape(s); }

// A coordinate or a tick's value: never "nan" or "inf" in the page (a non-finite value is 0;
// the plot's callers pass finite values only).
std::string num(double v, int decimals = 1) {
  if (!std::isfinite(v)) v = 0;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// A table's figure: "-" without a value (NaN), as the rows print it.
std::string figure(double v, int decimals = 1) { return std::isnan(v) ? "-" : std::isinf(v) ? "inf" : num(v, decimals); }

// A 1-2-5 step about SPAN / TICKS long (SPAN > 0).
double nice_step(double span, int ticks) {
  const double raw = span / ticks, magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * magnitude >= raw) return m * magnitude;
  return 10 * magnitude;
}

int decimals_of(double step) { return step >= 1 ? 0 : step >= 0.1 ? 1 : 2; }

struct Point {
  double t_s, value;  // value NaN: a gap
};

// VALUE(sample) of SERIES in at most kPlotMaxPoints points: each window of consecutive samples
// as its largest finite value at that sample's time, a gap when the window has none.
template <typename Value>
std::vector<Point> decimate(const std::vector<SeriesSample>& series, Value value) {
  const std::size_t n = series.size(), window = std::max<std::size_t>(1, (n + kPlotMaxPoints - 1) / kPlotMaxPoints);
  std::vector<Point> out;
  for (std::size_t a = 0; a < n; a += window) {
    Point p{series[a].t_s, std::nan("")};
    for (std::size_t k = a; k < std::min(n, a + window); ++k) {
      const double v = value(series[k]);
      if (std::isfinite(v) && (std::isnan(p.value) || v > p.value)) p = {series[k].t_s, v};
    }
    out.push_back(p);
  }
  return out;
}

// Time (s) and values to SVG px: force (N) on the left axis, stretch (%) on the right.
struct Frame {
  double t0 = 0, t1 = 1, force_step = 1, force_top = 1, stretch_step = 1, stretch_top = 1;
  [[nodiscard]] double x(double t) const { return kL + (kW - kL - kR) * std::clamp((t - t0) / (t1 - t0), 0.0, 1.0); }
  [[nodiscard]] double y(double v, double top) const {
    return kPlotBottom - (kPlotBottom - kPlotTop) * std::clamp(v / top, 0.0, 1.0);
  }
};

// POINTS as polylines of class CLS, one per run between gaps (a lone point drawn as a dot).
std::string polylines(const std::vector<Point>& points, const Frame& f, double top, const char* cls,
                      const char* colour) {
  std::string s, run;
  int run_points = 0;
  const auto flush = [&] {
    if (run_points == 1) run += " " + run;
    if (run_points > 0)
      s += std::string("<polyline class=\"") + cls + "\" points=\"" + run + "\" fill=\"none\" stroke=\"" + colour +
           "\" stroke-width=\"1.3\" stroke-linecap=\"round\" stroke-linejoin=\"round\"/>";
    run.clear();
    run_points = 0;
  };
  for (const Point& p : points) {
    if (std::isnan(p.value)) {
      flush();
      continue;
    }
    run += (run_points++ > 0 ? " " : "") + num(f.x(p.t_s)) + "," + num(f.y(p.value, top));
  }
  flush();
  return s;
}

// The states along the top: a band per transition until the next (the last to the plot's
// end), coloured by its path; the path, its start and why in the band's tooltip; the path's
// last part written in it where it fits; a thin line down the plot at each transition.
std::string state_bands(const std::vector<TimelineEntry>& timeline, const Frame& f) {
  static constexpr const char* kPalette[] = {"#8dd3c7", "#fdb462", "#bebada", "#fb8072", "#80b1d3",
                                             "#b3de69", "#fccde5", "#d9d9d9", "#bc80bd", "#ffed6f"};
  std::string s;
  for (std::size_t i = 0; i < timeline.size(); ++i) {
    const TimelineEntry& e = timeline[i];
    const double x0 = f.x(e.t_s), x1 = f.x(i + 1 < timeline.size() ? timeline[i + 1].t_s : f.t1);
    std::uint32_t hash = 2166136261u;  // FNV-1a: a path keeps its colour across trials
    for (char c : e.path) hash = (hash ^ static_cast<unsigned char>(c)) * 16777619u;
    const std::string tip = e.path + " from " + num(e.t_s, 2) + " s" + (e.why.empty() ? "" : ": " + e.why);
    s += "<line x1=\"" + num(x0) + "\" y1=\"" + num(kBandTop) + "\" x2=\"" + num(x0) + "\" y2=\"" + num(kPlotBottom) +
         "\" stroke=\"#ccc\"/>";
    s += "<rect class=\"state\" x=\"" + num(x0) + "\" y=\"" + num(kBandTop) + "\" width=\"" +
         num(std::max(x1 - x0, 1.0)) + "\" height=\"" + num(kBandH) + "\" fill=\"" + kPalette[hash % 10] +
         "\" stroke=\"#fff\"><title>" + esc(tip) + "</title></rect>";
    // The label: the longest tail of the path (whole parts) that fits, about 6.5 px a letter.
    for (std::size_t from = 0; from != std::string::npos; from = e.path.find('/', from + 1)) {
      const std::string label = e.path.substr(from == 0 ? 0 : from + 1);
      if (x1 - x0 < 6.5 * static_cast<double>(label.size()) + 6) continue;
      s += "<text class=\"band\" x=\"" + num(x0 + 3) + "\" y=\"" + num(kBandTop + 15) + "\">" + esc(label) + "</text>";
      break;
    }
  }
  return s;
}

// The time axis (bottom, s), the force axis (left, N, labels of class "fl") and the stretch
// axis (right, %, class "sl") with the torn threshold; each label's y is its tick's.
std::string axes(const Frame& f) {
  std::string s = "<rect x=\"" + num(kL) + "\" y=\"" + num(kPlotTop) + "\" width=\"" + num(kW - kL - kR) +
                  "\" height=\"" + num(kPlotBottom - kPlotTop) + "\" fill=\"none\" stroke=\"#555\"/>";
  const double ts = nice_step(f.t1 - f.t0, 10);
  for (double k = std::ceil(f.t0 / ts); k * ts <= f.t1 + 1e-9 * ts; ++k)
    s += "<text x=\"" + num(f.x(k * ts)) + "\" y=\"" + num(kPlotBottom + 15) + "\" text-anchor=\"middle\">" +
         num(k * ts, decimals_of(ts)) + "</text>";
  for (int k = 0; k * f.force_step <= f.force_top * (1 + 1e-9); ++k) {
    const double y = f.y(k * f.force_step, f.force_top);
    s += "<line x1=\"" + num(kL) + "\" y1=\"" + num(y) + "\" x2=\"" + num(kW - kR) + "\" y2=\"" + num(y) +
         "\" stroke=\"#e4e4e4\"/><text class=\"fl\" x=\"" + num(kL - 5) + "\" y=\"" + num(y) +
         "\" dy=\"4\" text-anchor=\"end\">" + num(k * f.force_step, decimals_of(f.force_step)) + "</text>";
  }
  for (int k = 0; k * f.stretch_step <= f.stretch_top * (1 + 1e-9); ++k)
    s += "<text class=\"sl\" x=\"" + num(kW - kR + 5) + "\" y=\"" + num(f.y(k * f.stretch_step, f.stretch_top)) +
         "\" dy=\"4\" fill=\"" + kStretchColour + "\">" + num(k * f.stretch_step, decimals_of(f.stretch_step)) +
         "</text>";
  const double torn_y = f.y(100 * kTornStretch, f.stretch_top);
  s += "<line x1=\"" + num(kL) + "\" y1=\"" + num(torn_y) + "\" x2=\"" + num(kW - kR) + "\" y2=\"" + num(torn_y) +
       "\" stroke=\"" + kStretchColour + "\" stroke-dasharray=\"6,4\"/><text x=\"" + num(kW - kR - 4) + "\" y=\"" +
       num(torn_y - 4) + "\" text-anchor=\"end\" fill=\"" + kStretchColour + "\">torn " +
       num(100 * kTornStretch, 0) + " %</text>";
  s += "<text x=\"" + num((kL + kW - kR) / 2) + "\" y=\"" + num(kH - 8) +
       "\" text-anchor=\"middle\">time since the sequence's start (s)</text>";
  s += "<text transform=\"rotate(-90)\" x=\"" + num(-(kPlotTop + kPlotBottom) / 2) +
       "\" y=\"16\" text-anchor=\"middle\">fingertip force (N)</text>";
  s += "<text transform=\"rotate(90)\" x=\"" + num((kPlotTop + kPlotBottom) / 2) + "\" y=\"" + num(-(kW - 14)) +
       "\" text-anchor=\"middle\" fill=\"" + kStretchColour + "\">stretch (%)</text>";
  return s;
}

// One trial over time, or "no samples" without a series.
std::string plot(const TrialResult& r) {
  if (r.series.empty()) return "<p class=\"none\">no samples</p>\n";
  Frame f;
  f.t0 = std::min(0.0, r.series.front().t_s);
  f.t1 = std::max(r.series.back().t_s, r.timeline.empty() ? f.t0 : r.timeline.back().t_s);
  if (!(f.t1 > f.t0)) f.t1 = f.t0 + 1;
  double force_max = 0, stretch_max = 0;  // N, %
  for (const SeriesSample& x : r.series) {
    for (double v : x.force_n)
      if (std::isfinite(v)) force_max = std::max(force_max, v);
    for (double v : x.measured_n)
      if (std::isfinite(v)) force_max = std::max(force_max, v);
    if (std::isfinite(x.stretch)) stretch_max = std::max(stretch_max, 100 * x.stretch);
  }
  f.force_step = nice_step(force_max > 0 ? force_max : 1, 4);
  f.force_top = std::ceil(std::max(force_max, f.force_step) / f.force_step) * f.force_step;
  stretch_max = std::max(stretch_max, 120 * kTornStretch);  // the threshold always inside
  f.stretch_step = nice_step(stretch_max, 4);
  f.stretch_top = std::ceil(stretch_max / f.stretch_step) * f.stretch_step;

  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(kW, 0) + "\" height=\"" + num(kH, 0) +
                  "\" viewBox=\"0 0 " + num(kW, 0) + " " + num(kH, 0) + "\" role=\"img\"><title>trial " +
                  std::to_string(r.index) + " over time</title>";
  s += axes(f) + state_bands(r.timeline, f);
  s += polylines(decimate(r.series, [](const SeriesSample& x) { return 100 * x.stretch; }), f, f.stretch_top,
                 "stretch", kStretchColour);
  for (int h = 0; h < 2; ++h)
    s += polylines(decimate(r.series, [h](const SeriesSample& x) { return x.force_n[h]; }), f, f.force_top,
                   h == 0 ? "force-r" : "force-l", kForceColour[h]) +
         polylines(decimate(r.series, [h](const SeriesSample& x) { return x.measured_n[h]; }), f, f.force_top,
                   h == 0 ? "measured-r" : "measured-l", kForceColour[h]);
  return s + "</svg>\n";
}

// The summary line's `key=value` words as a table, the line itself above it.
std::string summary_table(const std::string& line) {
  std::string keys, values;
  const std::size_t colon = line.find(": ");
  for (std::size_t a = colon == std::string::npos ? 0 : colon + 2; a < line.size();) {
    const std::size_t b = std::min(line.find(' ', a), line.size());
    const std::string word = line.substr(a, b - a);
    const std::size_t eq = word.find('=');
    keys += "<th>" + esc(eq == std::string::npos ? "" : word.substr(0, eq)) + "</th>";
    values += "<td>" + esc(eq == std::string::npos ? word : word.substr(eq + 1)) + "</td>";
    a = b + 1;
  }
  return "<p><code>" + esc(line) + "</code></p>\n<table><tr>" + keys + "</tr><tr>" + values + "</tr></table>\n";
}

std::string row_html(const TrialResult& r) {
  const Score& s = r.score;
  const std::string why = r.failure.empty() ? (r.error.empty() ? "failed" : r.error) : r.failure;
  return "<tr><td><a href=\"#trial-" + std::to_string(r.index) + "\">" + std::to_string(r.index) + "</a></td><td>" +
         std::to_string(r.seed) + "</td><td class=\"l\">" + esc(r.end) + "</td><td>" + std::to_string(r.fold_states) +
         "</td><td class=\"l\">" + esc(r.last_fold_state.empty() ? "-" : r.last_fold_state) + "</td><td>" +
         figure(r.fold_time_s) + "</td><td>" + figure(s.fold_line_mm) + "</td><td>" + figure(s.fold_angle_deg) +
         "</td><td>" + figure(s.corners_mm) + "</td><td>" + figure(s.retained_deg) + "</td><td>" +
         figure(100 * s.max_stretch, 2) + "</td><td>" + figure(s.slip_mm) + "</td><td>" +
         (r.hands_clear ? "yes" : "no") + "</td><td class=\"l\">" +
         (r.success ? std::string("<span class=\"yes\">success</span>") : "<span class=\"no\">" + esc(why) + "</span>") +
         "</td></tr>\n";
}

}  // namespace

std::string trials_html(const std::vector<TrialResult>& results, const std::string& fold, bool faults) {
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>crease-trials: fold " +
                  esc(fold) + "</title><style>" + kStyle + "</style></head><body>\n<h1>Folding trials: fold " +
                  esc(fold) + "</h1>\n" + summary_table(summary_line(results, fold, faults));
  h += "<h2>Trials</h2><table><tr><th>trial</th><th>seed</th><th class=\"l\">end</th><th>states</th>"
       "<th class=\"l\">last state</th><th>time s</th><th>fold line mm</th><th>angle deg</th><th>corners mm</th>"
       "<th>retained deg</th><th>stretch %</th><th>slip mm</th><th>hands clear</th><th class=\"l\">result</th></tr>\n";
  for (const TrialResult& r : results) h += row_html(r);
  h += std::string("</table>\n<h2>Over time</h2>\n<p>Along the top the sequence's states (a band each; its path in "
                   "the tooltip). <span style=\"color:") +
       kForceColour[0] + "\">right hand</span> and <span style=\"color:" + kForceColour[1] +
       "\">left hand</span>: the largest fingertip normal force (N, left axis; each point the largest of its "
       "window), solid as the world has it, dashed as the hand's force controller measured it (its tactile sensors). "
       "<span style=\"color:" + kStretchColour +
       "\">stretch</span>: the sheet's largest edge stretch (%, right axis), torn above " +
       num(100 * kTornStretch, 0) + " %.</p>\n";
  for (const TrialResult& r : results)
    h += "<h3 id=\"trial-" + std::to_string(r.index) + "\">trial " + std::to_string(r.index) + ", seed " +
         std::to_string(r.seed) + ": " + esc(r.end) + (r.last_fold_state.empty() ? "" : " in " + esc(r.last_fold_state)) +
         "</h3>\n" + (r.draws.empty() ? "" : "<p class=\"draws\">" + esc(r.draws) + "</p>\n") + plot(r);
  return h + "</body></html>\n";
}

}  // namespace crease::trials
