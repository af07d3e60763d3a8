// The HTML report: one file, inline CSS and SVG, no scripts, no network.
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/report/render.h"

namespace crease::report {

std::string html_escape(std::string_view s) {
  std::string o;
  o.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&#39;"; break;
      default: o += c;
    }
  }
  return o;
}

namespace {

std::string esc(const std::string& s) { return html_escape(s); }

std::string num(double v, int decimals = 1) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

std::string us(std::int64_t ns) { return num(static_cast<double>(ns) / 1e3); }

// "1 us", "10 us", "1 ms", ... for a power-of-ten tick in ns.
std::string tick_label(double ns) {
  if (ns >= 1e9) return num(ns / 1e9, 0) + " s";
  if (ns >= 1e6) return num(ns / 1e6, 0) + " ms";
  if (ns >= 1e3) return num(ns / 1e3, 0) + " us";
  return num(ns, 0) + " ns";
}

constexpr const char* kStyle = R"(
body{font-family:sans-serif;margin:24px;color:#222;background:#fff}
h1{font-size:22px}h2{font-size:18px;margin-top:28px;border-bottom:1px solid #ccc}
h3{font-size:15px}
table{border-collapse:collapse;margin:8px 0;font-size:13px}
td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}
th{background:#eef}td.l,th.l{text-align:left}
.yes{color:#070;font-weight:bold}.no{color:#a00;font-weight:bold}
.plots{display:flex;flex-wrap:wrap;gap:16px}
svg{background:#fafafa;border:1px solid #ddd}
svg text{font-family:sans-serif;font-size:11px;fill:#333}
)";

// A log-x, log-y bar plot of a distribution with percentile markers.
std::string svg_histogram(const Distribution& d, const std::string& title, const char* color) {
  const double W = 540, H = 240, L = 50, R = 15, T = 24, B = 36;
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"540\" height=\"240\" "
                  "viewBox=\"0 0 540 240\" role=\"img\"><title>" + esc(title) + "</title>";
  s += "<text x=\"" + num(L, 0) + "\" y=\"16\" font-weight=\"bold\">" + esc(title) + "</text>";
  if (d.buckets.empty()) {
    return s + "<text x=\"200\" y=\"120\">no samples</text></svg>";
  }
  double lo = std::max(1.0, static_cast<double>(d.buckets.front().lower_ns));
  double hi = std::max(lo * 10, static_cast<double>(d.buckets.back().upper_ns + 1));
  lo = std::pow(10.0, std::floor(std::log10(lo)));
  hi = std::pow(10.0, std::ceil(std::log10(hi)));
  std::uint64_t cmax = 1;
  for (const Bucket& b : d.buckets) cmax = std::max(cmax, b.count);
  const auto x = [&](double ns) {
    return L + (W - L - R) * (std::log10(std::max(ns, lo)) - std::log10(lo)) /
                   (std::log10(hi) - std::log10(lo));
  };
  const auto y = [&](double c) {
    return H - B - (H - B - T) * std::log10(c + 1) / std::log10(static_cast<double>(cmax) + 1);
  };
  // axes and decade ticks
  s += "<line x1=\"" + num(L) + "\" y1=\"" + num(H - B) + "\" x2=\"" + num(W - R) + "\" y2=\"" +
       num(H - B) + "\" stroke=\"#555\"/>";
  s += "<line x1=\"" + num(L) + "\" y1=\"" + num(T) + "\" x2=\"" + num(L) + "\" y2=\"" +
       num(H - B) + "\" stroke=\"#555\"/>";
  for (double t = lo; t <= hi * 1.001; t *= 10) {
    s += "<line x1=\"" + num(x(t)) + "\" y1=\"" + num(H - B) + "\" x2=\"" + num(x(t)) +
         "\" y2=\"" + num(T) + "\" stroke=\"#ddd\"/>";
    s += "<text x=\"" + num(x(t)) + "\" y=\"" + num(H - B + 14) + "\" text-anchor=\"middle\">" +
         tick_label(t) + "</text>";
  }
  for (double c = 1; c <= static_cast<double>(cmax) * 1.001; c *= 10) {
    s += "<text x=\"" + num(L - 4) + "\" y=\"" + num(y(c) + 4) + "\" text-anchor=\"end\">" +
         num(c, 0) + "</text>";
  }
  s += "<text x=\"" + num((L + W) / 2) + "\" y=\"" + num(H - 6) +
       "\" text-anchor=\"middle\">duration (log), bar height: samples (log)</text>";
  for (const Bucket& b : d.buckets) {
    if (b.count == 0) continue;
    const double x0 = x(static_cast<double>(b.lower_ns));
    const double x1 = std::max(x0 + 1.0, x(static_cast<double>(b.upper_ns + 1)));
    const double y0 = y(static_cast<double>(b.count));
    s += "<rect x=\"" + num(x0) + "\" y=\"" + num(y0) + "\" width=\"" + num(x1 - x0) +
         "\" height=\"" + num(H - B - y0) + "\" fill=\"" + color + "\"><title>" +
         us(b.lower_ns) + "-" + us(b.upper_ns) + " us: " + std::to_string(b.count) +
         "</title></rect>";
  }
  const std::pair<const char*, std::int64_t> marks[] = {
      {"p50", d.p50_ns}, {"p99", d.p99_ns}, {"p99.9", d.p999_ns}, {"max", d.max_ns}};
  int k = 0;
  for (const auto& [name, v] : marks) {
    if (v <= 0) continue;
    const double xv = x(static_cast<double>(v));
    s += "<line x1=\"" + num(xv) + "\" y1=\"" + num(T) + "\" x2=\"" + num(xv) + "\" y2=\"" +
         num(H - B) + "\" stroke=\"#c00\" stroke-dasharray=\"3,3\"/>";
    s += "<text x=\"" + num(xv + 2) + "\" y=\"" + num(T + 10 + 11 * (k++)) + "\" fill=\"#c00\">" +
         name + "</text>";
  }
  return s + "</svg>";
}

// Events and worst cycles along the run's time axis.
std::string svg_timeline(const TimingReport& r) {
  const double W = 1120, L = 110, R = 20;
  const double rows = static_cast<double>(r.loops.size()) + 1;
  const double H = 40 + 28 * rows;
  const double span = std::max(1e-9, r.duration_s());
  const auto x = [&](std::int64_t t) {
    return L + (W - L - R) * std::clamp((t - r.start_ns) * 1e-9 / span, 0.0, 1.0);
  };
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(W, 0) +
                  "\" height=\"" + num(H, 0) + "\" viewBox=\"0 0 " + num(W, 0) + " " + num(H, 0) +
                  "\" role=\"img\"><title>timeline</title>";
  for (int i = 0; i <= 10; ++i) {
    const double xv = L + (W - L - R) * i / 10.0;
    s += "<line x1=\"" + num(xv) + "\" y1=\"10\" x2=\"" + num(xv) + "\" y2=\"" + num(H - 22) +
         "\" stroke=\"#e4e4e4\"/><text x=\"" + num(xv) + "\" y=\"" + num(H - 8) +
         "\" text-anchor=\"middle\">" + num(span * i / 10.0, 2) + " s</text>";
  }
  double row_y = 28;
  s += "<text x=\"4\" y=\"" + num(row_y + 4) + "\">events</text>";
  for (const Event& e : r.events) {
    const bool fault = e.kind == "fault" || e.kind == "device_fault";
    const char* color = fault ? "#c00" : (e.kind == "hot_swap" ? "#06c" : (e.kind == "mark" ? "#090" : "#888"));
    s += "<circle cx=\"" + num(x(e.time_ns)) + "\" cy=\"" + num(row_y) + "\" r=\"6\" fill=\"" +
         color + "\"><title>" + esc(e.kind + " " + e.loop + "/" + e.plugin + " " + e.detail) +
         "</title></circle>";
  }
  for (const LoopTiming& l : r.loops) {
    row_y += 28;
    s += "<text x=\"4\" y=\"" + num(row_y + 4) + "\">" + esc(l.name) + " worst</text>";
    for (const CycleSample& w : l.wakeup_latency.worst) {
      s += "<rect x=\"" + num(x(w.time_ns) - 3) + "\" y=\"" + num(row_y - 6) +
           "\" width=\"6\" height=\"12\" fill=\"#e80\"><title>cycle " + std::to_string(w.cycle) +
           ": wake-up " + us(w.value_ns) + " us</title></rect>";
    }
  }
  return s + "</svg>";
}

std::string yes_no(bool v) { return v ? "<span class=\"yes\">yes</span>" : "<span class=\"no\">no</span>"; }

std::string dist_cells(const Distribution& d) {
  std::string s = "<td>" + std::to_string(d.count) + "</td>";
  for (std::int64_t v : {d.p50_ns, d.p90_ns, d.p99_ns, d.p999_ns, d.p9999_ns, d.max_ns}) {
    s += "<td>" + us(v) + "</td>";
  }
  return s;
}

constexpr const char* kDistHead =
    "<th>samples</th><th>p50</th><th>p90</th><th>p99</th><th>p99.9</th><th>p99.99</th>"
    "<th>max</th>";

}  // namespace

std::string render_html(const TimingReport& r) {
  const MachineInfo& m = r.machine;
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" +
                  esc(r.title) + "</title><style>" + kStyle + "</style></head><body>\n";
  h += "<h1>" + esc(r.title) + "</h1>\n<p>";
  if (!r.config_file.empty()) h += "Configuration <code>" + esc(r.config_file) + "</code>. ";
  if (!r.wall_clock.empty()) h += "Written " + esc(r.wall_clock) + ". ";
  h += "Duration " + num(r.duration_s(), 3) + " s. All times in microseconds.</p>\n";

  h += "<h2>Machine</h2><table>";
  h += "<tr><th class=\"l\">host</th><td class=\"l\">" + esc(m.hostname) + "</td></tr>";
  h += "<tr><th class=\"l\">kernel</th><td class=\"l\">" + esc(m.kernel) + "</td></tr>";
  h += "<tr><th class=\"l\">CPU</th><td class=\"l\">" + esc(m.cpu_model) + " (" +
       std::to_string(m.cpu_count) + " CPUs)</td></tr>";
  h += "<tr><th class=\"l\">preemption</th><td class=\"l\">" + esc(m.preemption) + "</td></tr>";
  h += "<tr><th class=\"l\">SCHED_FIFO applied</th><td class=\"l\">" + yes_no(m.sched_fifo_applied) + "</td></tr>";
  h += "<tr><th class=\"l\">CPU affinity applied</th><td class=\"l\">" + yes_no(m.affinity_applied) + "</td></tr>";
  h += "<tr><th class=\"l\">mlockall applied</th><td class=\"l\">" + yes_no(m.mlockall_applied) + "</td></tr>";
  h += "<tr><th class=\"l\">non-real-time threads on CPUs</th><td class=\"l\">" +
       esc(m.non_rt_cpus.empty() ? std::string("any") : m.non_rt_cpus) + "</td></tr>";
  h += "</table>\n";
  h += "<h2>Threads</h2><table><tr><th class=\"l\">thread</th><th>tid</th><th class=\"l\">CPUs</th>"
       "<th class=\"l\">policy</th><th>priority</th></tr>";
  for (const ThreadPlacement& t : m.threads) {
    h += "<tr><td class=\"l\">" + esc(t.name) + "</td><td>" + std::to_string(t.tid) + "</td><td class=\"l\">" +
         esc(t.cpus) + "</td><td class=\"l\">" + esc(t.policy) + "</td><td>" + std::to_string(t.priority) +
         "</td></tr>";
  }
  h += "</table>\n";

  h += "<h2>Loops</h2><table><tr><th class=\"l\">loop</th><th>rate Hz</th><th>priority</th>"
       "<th>cpu</th><th>cycles</th><th>overruns</th><th>missed deadlines</th>";
  h += std::string(kDistHead) + "</tr>";
  for (const LoopTiming& l : r.loops) {
    h += "<tr><td class=\"l\">" + esc(l.name) + "</td><td>" + num(l.rate_hz, 1) + "</td><td>" +
         std::to_string(l.priority) + "</td><td>" + std::to_string(l.cpu) + "</td><td>" +
         std::to_string(l.cycles) + "</td><td>" + std::to_string(l.overruns) + "</td><td>" +
         std::to_string(l.missed_deadlines) + "</td>" + dist_cells(l.wakeup_latency) +
         "</tr>";
  }
  h += "</table><p>Percentiles: wake-up latency.</p>\n<h2>Timeline</h2>\n" + svg_timeline(r) + "\n";

  for (const LoopTiming& l : r.loops) {
    h += "<h2>Loop " + esc(l.name) + "</h2>\n<div class=\"plots\">" +
         svg_histogram(l.wakeup_latency, l.name + ": wake-up latency", "#3a7bd5") +
         svg_histogram(l.execution, l.name + ": execution time (all plugins)", "#4a4") +
         "</div>\n";
    h += std::string("<h3>Execution time per plugin</h3><table><tr><th class=\"l\">plugin</th>"
                     "<th class=\"l\">library</th><th class=\"l\">state</th><th>faults</th>"
                     "<th>swaps</th><th class=\"l\">health</th><th>budget us</th><th>over budget</th>"
                     "<th>RT allocations</th><th>device faults</th>") + kDistHead + "</tr>";
    h += "<tr><td class=\"l\"><i>whole cycle</i></td><td></td><td></td><td></td><td></td>"
         "<td></td><td></td><td></td><td></td><td></td>" +
         dist_cells(l.execution) + "</tr>";
    for (const PluginTiming& p : l.plugins) {
      h += "<tr><td class=\"l\">" + esc(p.name) + "</td><td class=\"l\">" + esc(p.library) +
           "</td><td class=\"l\">" + esc(p.state) + "</td><td>" + std::to_string(p.faults) +
           "</td><td>" + std::to_string(p.swaps) + "</td><td class=\"l\">" + esc(p.health) + "</td><td>" +
           (p.budget_us > 0 ? num(p.budget_us) : std::string("none")) + "</td><td>" + std::to_string(p.over_budget) +
           "</td><td>" + std::to_string(p.rt_allocations) + "</td><td>" + std::to_string(p.device_faults) + "</td>" +
           dist_cells(p.execution) + "</tr>";
    }
    h += "</table>\n<div class=\"plots\">";
    for (const PluginTiming& p : l.plugins) {
      h += svg_histogram(p.execution, p.name + ": execution time", "#a5a");
    }
    h += "</div>\n<h3>Worst wake-ups</h3><table><tr><th>cycle</th><th>time s</th>"
         "<th>latency us</th></tr>";
    for (const CycleSample& w : l.wakeup_latency.worst) {
      h += "<tr><td>" + std::to_string(w.cycle) + "</td><td>" +
           num((w.time_ns - r.start_ns) * 1e-9, 6) + "</td><td>" + us(w.value_ns) + "</td></tr>";
    }
    h += "</table>\n";
  }

  h += "<h2>Ports</h2><table><tr><th class=\"l\">port</th><th class=\"l\">kind</th>"
       "<th class=\"l\">type</th><th>bytes</th><th class=\"l\">writer</th><th class=\"l\">readers</th>"
       "<th>writes</th><th>dropped</th><th>capacity</th><th>consumed</th><th class=\"l\">cameras</th></tr>";
  for (const PortTraffic& p : r.ports) {
    std::string readers, cameras;
    for (const std::string& x : p.readers) readers += (readers.empty() ? "" : ", ") + x;
    for (const std::string& c : p.cameras) cameras += (cameras.empty() ? "" : ", ") + c;
    h += "<tr><td class=\"l\">" + esc(p.name) + "</td><td class=\"l\">" + esc(p.kind) + "</td><td class=\"l\">" +
         esc(p.type) + " v" + std::to_string(p.version) + "</td><td>" + std::to_string(p.size) +
         "</td><td class=\"l\">" + esc(p.writer) + "</td><td class=\"l\">" + esc(readers) + "</td><td>" +
         std::to_string(p.writes) + "</td><td>" + std::to_string(p.dropped) + "</td><td>" +
         (p.kind == "queue" ? std::to_string(p.capacity) : "") + "</td><td>" +
         (p.kind == "frames" ? std::to_string(p.consumed) : "") + "</td><td class=\"l\">" + esc(cameras) +
         "</td></tr>";
  }
  h += "</table>\n";

  h += "<h2>Figures</h2><table><tr><th class=\"l\">figure</th><th class=\"l\">port</th><th>mean</th>"
       "<th>last</th><th>worst</th><th class=\"l\">unit</th><th>samples</th></tr>";
  for (const FigureSummary& f : r.figures) {
    h += "<tr><td class=\"l\">" + esc(f.label) + "</td><td class=\"l\">" + esc(f.port) + "</td><td>" + num(f.mean, 3) +
         "</td><td>" + num(f.last, 3) + "</td><td>" + num(f.max, 3) + "</td><td class=\"l\">" + esc(f.unit) +
         "</td><td>" + std::to_string(f.count) + " " + esc(f.sample) + "</td></tr>";
  }
  h += "</table>\n";

  h += "<h2>Events</h2><table><tr><th>time s</th><th class=\"l\">kind</th><th class=\"l\">loop"
       "</th><th class=\"l\">plugin</th><th class=\"l\">detail</th></tr>";
  for (const Event& e : r.events) {
    h += "<tr><td>" + num((e.time_ns - r.start_ns) * 1e-9, 6) + "</td><td class=\"l\">" +
         esc(e.kind) + "</td><td class=\"l\">" + esc(e.loop) + "</td><td class=\"l\">" +
         esc(e.plugin) + "</td><td class=\"l\">" + esc(e.detail) + "</td></tr>";
  }
  h += "</table>\n</body></html>\n";
  return h;
}

}  // namespace crease::report
