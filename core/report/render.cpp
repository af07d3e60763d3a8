#include "core/report/render.h"

#include <algorithm>
#include <cinttypes>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/report/report_json.h"

namespace crease::report {
namespace {

// printf into a std::string (its format checked at each call).
[[gnu::format(printf, 2, 3)]] void appendf(std::string& out, const char* fmt, ...) {
  char buf[512];
  std::va_list args;
  va_start(args, fmt);
  std::va_list again;
  va_copy(again, args);
  const int n = std::vsnprintf(buf, sizeof(buf), fmt, args);
  va_end(args);
  if (n > 0 && static_cast<std::size_t>(n) < sizeof(buf)) {
    out.append(buf, static_cast<std::size_t>(n));
  } else if (n > 0) {
    std::string big(static_cast<std::size_t>(n) + 1, '\0');
    std::vsnprintf(big.data(), big.size(), fmt, again);
    big.pop_back();
    out += big;
  }
  va_end(again);
}

unsigned long us(std::int64_t ns) { return static_cast<unsigned long>(std::max<std::int64_t>(ns, 0) / 1000); }

// The cyclictest row (microsecond) a bucket's samples are attributed to: its midpoint.
std::int64_t row_of(const Bucket& b) { return (b.lower_ns + (b.upper_ns - b.lower_ns) / 2) / 1000; }

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  return s;
}

void append_percentiles(std::string& out, const char* label, const Distribution& d) {
  appendf(out,
          "#   %-28s n=%" PRIu64 " min=%.1f p50=%.1f p90=%.1f p99=%.1f p99.9=%.1f p99.99=%.1f "
          "max=%.1f mean=%.1f (us)\n",
          label, d.count, d.min_ns / 1e3, d.p50_ns / 1e3, d.p90_ns / 1e3, d.p99_ns / 1e3,
          d.p999_ns / 1e3, d.p9999_ns / 1e3, d.max_ns / 1e3, d.mean_ns / 1e3);
}

}  // namespace

std::optional<Format> parse_format(std::string_view name) {
  if (name == "text" || name == "txt") return Format::text;
  if (name == "json") return Format::json;
  if (name == "html") return Format::html;
  return std::nullopt;
}

const char* to_string(Format f) noexcept {
  switch (f) {
    case Format::text: return "text";
    case Format::json: return "json";
    case Format::html: return "html";
  }
  return "?";
}

const char* file_extension(Format f) noexcept {
  switch (f) {
    case Format::text: return "txt";
    case Format::json: return "json";
    case Format::html: return "html";
  }
  return "?";
}

std::string render_text(const TimingReport& r) {
  std::string out;
  const MachineInfo& m = r.machine;
  appendf(out, "# %s\n", one_line(r.title).c_str());
  if (!r.config_file.empty()) appendf(out, "# config: %s\n", one_line(r.config_file).c_str());
  if (!r.wall_clock.empty()) appendf(out, "# time: %s\n", one_line(r.wall_clock).c_str());
  appendf(out, "# duration_s: %.3f\n", r.duration_s());
  appendf(out, "# machine: %s; %s; %s; %d cpus; preemption %s\n", one_line(m.hostname).c_str(),
          one_line(m.kernel).c_str(), one_line(m.cpu_model).c_str(), m.cpu_count,
          m.preemption.c_str());
  appendf(out, "# applied: sched_fifo=%s affinity=%s mlockall=%s\n",
          m.sched_fifo_applied ? "yes" : "no", m.affinity_applied ? "yes" : "no",
          m.mlockall_applied ? "yes" : "no");
  appendf(out, "# non-real-time threads on CPUs: %s\n", m.non_rt_cpus.empty() ? "any" : m.non_rt_cpus.c_str());
  for (const ThreadPlacement& t : m.threads) {
    appendf(out, "# thread: %s tid=%d cpus=%s policy=%s priority=%d\n", one_line(t.name).c_str(), t.tid,
            t.cpus.c_str(), t.policy.c_str(), t.priority);
  }
  appendf(out, "# columns: wake-up latency per loop, one row per microsecond\n");
  for (std::size_t i = 0; i < r.loops.size(); ++i) {
    const LoopTiming& l = r.loops[i];
    appendf(out, "# column %zu: loop %s rate_hz=%g priority=%d cpu=%d\n", i, l.name.c_str(),
            l.rate_hz, l.priority, l.cpu);
  }

  // cyclictest -h block.
  std::int64_t max_us = 0;
  for (const LoopTiming& l : r.loops) max_us = std::max<std::int64_t>(max_us, l.wakeup_latency.max_ns / 1000);
  const std::int64_t rows = std::clamp<std::int64_t>(max_us + 1, 1, kTextHistogramMaxUs);
  const std::size_t n = r.loops.size();
  std::vector<std::vector<std::uint64_t>> hist(n, std::vector<std::uint64_t>(static_cast<std::size_t>(rows), 0));
  std::vector<std::uint64_t> overflow(n, 0), total(n, 0);
  for (std::size_t j = 0; j < n; ++j) {
    for (const Bucket& b : r.loops[j].wakeup_latency.buckets) {
      const std::int64_t row = row_of(b);
      if (row < rows) {
        hist[j][static_cast<std::size_t>(row)] += b.count;
        total[j] += b.count;
      } else {
        overflow[j] += b.count;
      }
    }
  }
  out += "# Histogram\n";
  for (std::int64_t i = 0; i < rows; ++i) {
    appendf(out, "%06d ", static_cast<int>(i));
    for (std::size_t j = 0; j < n; ++j) {
      appendf(out, "%06lu", static_cast<unsigned long>(hist[j][static_cast<std::size_t>(i)]));
      if (j + 1 < n) out += '\t';
    }
    out += '\n';
  }
  out += "# Total:";
  for (std::size_t j = 0; j < n; ++j) appendf(out, " %09llu", static_cast<unsigned long long>(total[j]));
  out += "\n# Min Latencies:";
  for (const LoopTiming& l : r.loops) appendf(out, " %05lu", us(l.wakeup_latency.min_ns));
  out += "\n# Avg Latencies:";
  for (const LoopTiming& l : r.loops) appendf(out, " %05lu", us(static_cast<std::int64_t>(l.wakeup_latency.mean_ns)));
  out += "\n# Max Latencies:";
  for (const LoopTiming& l : r.loops) appendf(out, " %05lu", us(l.wakeup_latency.max_ns));
  out += "\n# Histogram Overflows:";
  for (std::size_t j = 0; j < n; ++j) appendf(out, " %05lu", static_cast<unsigned long>(overflow[j]));
  out += "\n# Histogram Overflow at cycle number:\n";
  for (std::size_t j = 0; j < n; ++j) {
    appendf(out, "# Thread %zu:", j);
    std::uint64_t listed = 0;
    for (const CycleSample& s : r.loops[j].wakeup_latency.worst) {
      if (s.value_ns / 1000 >= rows) {
        appendf(out, " %05lu", static_cast<unsigned long>(s.cycle));
        ++listed;
      }
    }
    if (listed < overflow[j]) appendf(out, " # %05lu others", static_cast<unsigned long>(overflow[j] - listed));
    out += '\n';
  }
  out += '\n';

  // Crease extras, all comments.
  out += "# Crease summary\n";
  for (const LoopTiming& l : r.loops) {
    appendf(out, "# loop %s: cycles=%" PRIu64 " overruns=%" PRIu64 " missed_deadlines=%" PRIu64 "\n",
            l.name.c_str(), l.cycles, l.overruns, l.missed_deadlines);
    append_percentiles(out, "wake-up latency", l.wakeup_latency);
    append_percentiles(out, "execution (all plugins)", l.execution);
    for (const CycleSample& s : l.wakeup_latency.worst) {
      appendf(out, "#   worst wake-up: cycle %" PRIu64 " at %.6f s: %.1f us\n", s.cycle,
              (s.time_ns - r.start_ns) * 1e-9, s.value_ns / 1e3);
    }
    for (const PluginTiming& p : l.plugins) {
      appendf(out,
              "#   plugin %s (%s, %s): faults=%" PRIu64 " swaps=%" PRIu64 " health=%s budget_us=%.1f over_budget=%" PRIu64
              " rt_allocations=%" PRIu64 " device_faults=%" PRIu64 "\n",
              p.name.c_str(), p.library.c_str(), p.state.c_str(), p.faults, p.swaps,
              p.health.empty() ? "-" : p.health.c_str(), p.budget_us, p.over_budget, p.rt_allocations, p.device_faults);
      append_percentiles(out, ("  execution " + p.name).c_str(), p.execution);
    }
  }
  out += "# Ports\n";
  for (const PortTraffic& p : r.ports) {
    std::string readers;
    for (const std::string& x : p.readers) readers += (readers.empty() ? "" : ",") + x;
    appendf(out, "#   port %s (%s %s v%u, %" PRIu64 " bytes): writer=%s readers=%s writes=%" PRIu64
            " dropped=%" PRIu64, p.name.c_str(), p.kind.c_str(), p.type.c_str(), p.version, p.size,
            p.writer.empty() ? "-" : p.writer.c_str(), readers.empty() ? "-" : readers.c_str(), p.writes,
            p.dropped);
    if (p.kind == "queue") appendf(out, " capacity=%" PRIu64, p.capacity);
    if (p.kind == "frames") {
      appendf(out, " consumed=%" PRIu64 " cameras=", p.consumed);
      for (std::size_t k = 0; k < p.cameras.size(); ++k) {
        out += (k == 0 ? "" : ",") + one_line(p.cameras[k]);
      }
    }
    out += '\n';
  }
  out += "# Figures\n";
  for (const FigureSummary& f : r.figures) {
    appendf(out, "#   %s (%s): mean %.3f %s over %" PRIu64 " %s, last %.3f, worst %.3f\n", one_line(f.label).c_str(),
            f.port.c_str(), f.mean, one_line(f.unit).c_str(), f.count, one_line(f.sample).c_str(), f.last, f.max);
  }
  out += "# Events\n";
  for (const Event& e : r.events) {
    appendf(out, "#   %.6f s %s loop=%s plugin=%s %s\n", (e.time_ns - r.start_ns) * 1e-9,
            e.kind.c_str(), e.loop.c_str(), e.plugin.c_str(), one_line(e.detail).c_str());
  }
  return out;
}

std::string render_json(const TimingReport& report) {
  return nlohmann::json(report).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) +
         "\n";
}

std::string render(const TimingReport& report, Format format) {
  switch (format) {
    case Format::text: return render_text(report);
    case Format::json: return render_json(report);
    case Format::html: return render_html(report);
  }
  return {};
}

std::vector<std::string> write_report_files(const TimingReport& report, const std::string& dir,
                                            const std::string& basename) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("report folder " + dir + ": " + ec.message());
  std::vector<std::string> paths;
  for (Format f : {Format::text, Format::json, Format::html}) {
    const std::string path = dir + "/" + basename + "." + file_extension(f);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << render(report, f);
    out.close();
    if (!out) throw Error("report " + path + ": cannot write");
    paths.push_back(path);
  }
  return paths;
}

}  // namespace crease::report
