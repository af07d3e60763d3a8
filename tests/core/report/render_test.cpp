// Tests for core/report: percentiles from buckets, the cyclictest-format text, JSON round
// trip, self-contained HTML, report files, conversion from rt histogram snapshots.
#include "core/report/render.h"

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "core/report/from_rt.h"
#include "core/report/report_json.h"
#include "core/report/report_fixture.h"

namespace rep = crease::report;

namespace {

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

bool has_line(const std::vector<std::string>& lines, const std::string& l) {
  return std::find(lines.begin(), lines.end(), l) != lines.end();
}

}  // namespace

TEST_CASE("percentiles are the upper bound of the bucket holding the rank, clamped to max") {
  const rep::Distribution d = rep::testing::wakeup_fixture();
  CHECK(d.count == 1112);
  CHECK(d.p50_ns == 5099);
  CHECK(d.p90_ns == 20499);
  CHECK(d.p99_ns == 153999);
  CHECK(d.p999_ns == 15200000);   // bucket upper 15499999 clamped to max
  CHECK(d.p9999_ns == 15200000);
  rep::Distribution empty;
  rep::fill_percentiles(empty);
  CHECK(empty.p99_ns == 0);
  CHECK(empty.empty());
}

TEST_CASE("text follows cyclictest's -h histogram format") {
  const std::string text = rep::render_text(rep::testing::report_fixture());
  const auto lines = lines_of(text);
  const auto hist = std::find(lines.begin(), lines.end(), "# Histogram");
  REQUIRE(hist != lines.end());
  // Every line before the histogram is a comment.
  for (auto it = lines.begin(); it != hist; ++it) CHECK(it->rfind("# ", 0) == 0);
  // 10000 rows (the largest latency is above the 10 ms range), two tab-separated columns.
  CHECK(*(hist + 1) == "000000 000000\t000000");
  CHECK(*(hist + 10000) == "009999 000000\t000000");
  CHECK(*(hist + 10001) == "# Total: 000001110 000000120");
  CHECK(has_line(lines, "000005 001000\t000000"));
  CHECK(has_line(lines, "000020 000100\t000000"));
  CHECK(has_line(lines, "000040 000000\t000120"));
  CHECK(has_line(lines, "000151 000010\t000000"));
  CHECK(has_line(lines, "# Min Latencies: 00005 00040"));
  CHECK(has_line(lines, "# Avg Latencies: 00034 00040"));
  CHECK(has_line(lines, "# Max Latencies: 15200 00040"));
  CHECK(has_line(lines, "# Histogram Overflows: 00002 00000"));
  CHECK(has_line(lines, "# Histogram Overflow at cycle number:"));
  CHECK(has_line(lines, "# Thread 0: 00900 00007"));
  CHECK(has_line(lines, "# Thread 1:"));
  // Exactly one "Max Latencies" line: scripts grep for it.
  CHECK(std::count_if(lines.begin(), lines.end(), [](const std::string& l) {
          return l.find("Max Latencies") != std::string::npos;
        }) == 1);
  // Non-comment, non-empty lines are exactly the histogram rows.
  CHECK(std::count_if(lines.begin(), lines.end(), [](const std::string& l) {
          return !l.empty() && l[0] != '#';
        }) == 10000);
  CHECK(text.find("loop control: cycles=1112 overruns=2 missed_deadlines=3") != std::string::npos);
  CHECK(text.find("plugin faulty (crease_faulty, faulted): faults=1") != std::string::npos);
  CHECK(text.find("0.500000 s hot_swap loop=control plugin=counter") != std::string::npos);
  CHECK(text.find("applied: sched_fifo=yes affinity=no mlockall=yes") != std::string::npos);
}

TEST_CASE("a short run prints only the rows it needs") {
  rep::TimingReport r;
  r.loops.resize(1);
  r.loops[0].name = "a";
  r.loops[0].wakeup_latency.buckets = {{2000, 2000, 3}};
  r.loops[0].wakeup_latency.max_ns = 2000;
  const auto lines = lines_of(rep::render_text(r));
  const auto hist = std::find(lines.begin(), lines.end(), "# Histogram");
  REQUIRE(hist != lines.end());
  CHECK(*(hist + 3) == "000002 000003");
  CHECK(*(hist + 4) == "# Total: 000000003");
}

TEST_CASE("JSON round-trips the model") {
  const rep::TimingReport r = rep::testing::report_fixture();
  const std::string text = rep::render_json(r);
  const auto j = nlohmann::json::parse(text);
  CHECK(j["loops"][0]["wakeup_latency"]["p99_ns"] == 153999);
  CHECK(j["duration_s"] == doctest::Approx(2.0));
  const rep::TimingReport back = j.get<rep::TimingReport>();
  CHECK(back.title == r.title);
  CHECK(back.machine.cpu_model == r.machine.cpu_model);
  CHECK(back.machine.sched_fifo_applied);
  REQUIRE(back.loops.size() == 2);
  CHECK(back.loops[0].plugins[1].faults == 1);
  CHECK(back.loops[0].wakeup_latency.worst[0].cycle == 900);
  CHECK(back.loops[0].wakeup_latency.buckets.size() == 4);
  CHECK(back.events[1].detail == "NaN on output <out>");
  REQUIRE(back.ports.size() == 3);
  CHECK(back.ports[1].kind == "frames");
  CHECK(back.ports[1].cameras.size() == 2);
  CHECK(back.ports[1].dropped == 4);
  CHECK(back.ports[0].capacity == 256);
  CHECK(rep::render_json(back) == text);
  CHECK_THROWS(nlohmann::json{{"title", "x"}}.get<rep::TimingReport>());
}

TEST_CASE("text and HTML list every port, frame channels with their cameras") {
  const rep::TimingReport r = rep::testing::report_fixture();
  const std::string text = rep::render_text(r);
  CHECK(text.find("# Ports\n") != std::string::npos);
  CHECK(text.find("#   port images (frames crease.FrameSet v1, 2457600 bytes): writer=cameras readers=vision "
                  "writes=30 dropped=4 consumed=29 cameras=cam0 1280x960,cam1 1280x960\n") != std::string::npos);
  CHECK(text.find("#   port crease (queue crease.SheetCreaseEvent v1, 32 bytes): writer=seq readers=sheet "
                  "writes=5 dropped=1 capacity=256\n") != std::string::npos);
  CHECK(text.find("#   port sheet_state (latest crease.SheetState v1, 360000 bytes): writer=sheet readers=ctrl "
                  "writes=120 dropped=0\n") != std::string::npos);
  const std::string html = rep::render_html(r);
  CHECK(html.find("<h2>Ports</h2>") != std::string::npos);
  CHECK(html.find("<td class=\"l\">images</td><td class=\"l\">frames</td>") != std::string::npos);
  CHECK(html.find("cam0 1280x960, cam1 1280x960") != std::string::npos);
}

TEST_CASE("HTML is one self-contained file with inline SVG and escaped text") {
  const std::string html = rep::render_html(rep::testing::report_fixture());
  CHECK(html.rfind("<!DOCTYPE html>", 0) == 0);
  CHECK(html.find("</html>") != std::string::npos);
  CHECK(html.find("<script") == std::string::npos);
  CHECK(html.find("<link") == std::string::npos);
  CHECK(html.find("src=") == std::string::npos);
  // The only URL is the SVG namespace.
  std::size_t urls = 0, svgs = 0;
  for (std::size_t p = html.find("http"); p != std::string::npos; p = html.find("http", p + 1)) {
    ++urls;
    CHECK(html.compare(p, 26, "http://www.w3.org/2000/svg") == 0);
  }
  for (std::size_t p = html.find("<svg"); p != std::string::npos; p = html.find("<svg", p + 1)) ++svgs;
  CHECK(urls == svgs);
  CHECK(svgs == 1 + 2 * 2 + 2);  // timeline, 2 plots per loop, one per plugin
  CHECK(html.find("&lt;test &amp; &quot;quotes&quot;&gt;") != std::string::npos);
  CHECK(html.find("<test &") == std::string::npos);
  CHECK(html.find("NaN on output &lt;out&gt;") != std::string::npos);
  CHECK(html.find("153.999") == std::string::npos);  // one decimal in us
  CHECK(html.find("<td>154.0</td>") != std::string::npos);
}

TEST_CASE("formats by name and report files on disk") {
  CHECK(rep::parse_format("html") == rep::Format::html);
  CHECK(rep::parse_format("json") == rep::Format::json);
  CHECK(rep::parse_format("text") == rep::Format::text);
  CHECK_FALSE(rep::parse_format("pdf").has_value());
  const std::string dir = "/tmp/crease_report_test_" + std::to_string(::getpid()) + "/a/b";
  const auto r = rep::testing::report_fixture();
  const auto paths = rep::write_report_files(r, dir, "run1");
  REQUIRE(paths.size() == 3);
  CHECK(paths[0] == dir + "/run1.txt");
  for (const auto& p : paths) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    CHECK(s.str().size() > 500);
  }
  std::filesystem::remove_all("/tmp/crease_report_test_" + std::to_string(::getpid()));
}

TEST_CASE("from_snapshot converts an rt histogram") {
  crease::rt::Histogram h;
  for (std::uint64_t i = 0; i < 1000; ++i) h.record(10000 + i, i, static_cast<std::int64_t>(i) * 1000000);
  h.record(500000, 1000, 1000000000);
  const rep::Distribution d = rep::from_snapshot(h.snapshot());
  CHECK(d.count == 1001);
  CHECK(d.max_ns == 500000);
  CHECK(d.min_ns == 10000);
  CHECK(d.p50_ns >= 10499);
  CHECK(d.p50_ns <= 10499 + 10499 / 32 + 1);
  CHECK(d.p9999_ns == 500000);
  REQUIRE_FALSE(d.worst.empty());
  CHECK(d.worst[0].cycle == 1000);
  CHECK(d.worst[0].value_ns == 500000);
  std::uint64_t sum = 0;
  for (const auto& b : d.buckets) sum += b.count;
  CHECK(sum == 1001);
}
