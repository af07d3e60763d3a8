// The report creased writes lists every port of the host, frame channels too.
#include "core/daemon/report_builder.h"

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "core/daemon/figures.h"
#include "core/port.h"
#include "core/port_types/figure.h"
#include "core/report/render.h"
#include "core/report/report_json.h"

TEST_CASE("the report lists the host's ports, a frame channel with its cameras and traffic") {
  crease::PluginHost host({});
  auto w = host.ports().bind_frames_writer("images", {{"cam0", 4, 2}}, "cameras");
  auto r = host.ports().bind_frames_reader("images", {{"cam0", 4, 2}}, "vision");
  w->publish(1, 1, 0x1);
  w->publish(2, 2, 0x1);
  REQUIRE(r->acquire_newest() != nullptr);
  crease::daemon::RunFacts facts;
  facts.config_file = "test.yaml";
  const crease::report::TimingReport rep = crease::daemon::build_report(host, facts);
  REQUIRE(rep.ports.size() == 1);
  const crease::report::PortTraffic& p = rep.ports[0];
  CHECK(p.name == "images");
  CHECK(p.kind == "frames");
  CHECK(p.type == "crease.FrameSet");
  CHECK(p.size == 8);
  CHECK(p.writer == "cameras");
  CHECK(p.readers == std::vector<std::string>{"vision"});
  CHECK(p.cameras == std::vector<std::string>{"cam0 4x2"});
  CHECK(p.writes == 2);
  CHECK(p.dropped == 1);
  CHECK(p.consumed == 2);
  const std::string text = crease::report::render_text(rep);
  CHECK(text.find("#   port images (frames crease.FrameSet v1, 8 bytes): writer=cameras readers=vision") !=
        std::string::npos);
}

TEST_CASE("the report and every rendering carry the figures the plugins report; an older report without them reads") {
  crease::PluginHost host({});
  auto* ch = host.ports().bind_latest_writer("detect_time", crease::port_type_of<crease::Figure>(), "vision");
  crease::Figure f = crease::Figure::named("vision detection per frame set", "ms", "frame sets");
  f.count = 4;
  f.sum = 100.0;
  f.last = 20.0;
  f.max = 40.0;
  ch->write(&f, 1);
  const crease::report::TimingReport rep = crease::daemon::build_report(host, crease::daemon::RunFacts{});
  REQUIRE(rep.figures.size() == 1);
  CHECK(rep.figures[0].port == "detect_time");
  CHECK(rep.figures[0].mean == doctest::Approx(25.0));
  CHECK(rep.figures[0].max == doctest::Approx(40.0));
  CHECK(crease::report::render_text(rep).find(
            "#   vision detection per frame set (detect_time): mean 25.000 ms over 4 frame sets, last 20.000, worst 40.000") !=
        std::string::npos);
  CHECK(crease::report::render(rep, crease::report::Format::html).find("<td class=\"l\">vision detection per frame set</td>") !=
        std::string::npos);
  nlohmann::json j = nlohmann::json::parse(crease::report::render(rep, crease::report::Format::json));
  CHECK(j["figures"][0]["label"] == "vision detection per frame set");
  CHECK(j.get<crease::report::TimingReport>().figures.size() == 1);
  j.erase("figures");
  CHECK(j.get<crease::report::TimingReport>().figures.empty());
}

// creased writes its report after the host stopped, which drives every output, a Figure port
// too, to its safe value (count 0): the report's figures are the ones taken before the stop, as
// the console's summary prints them (a report without them showed every figure at 0 samples).
TEST_CASE("the report written at the end carries the figures taken before the stop, not the safe values") {
  crease::PluginHost host({});
  auto* ch = host.ports().bind_latest_writer("tracking_error", crease::port_type_of<crease::Figure>(), "score");
  crease::Figure f = crease::Figure::named("tracking error", "mm", "model frames");
  f.count = 3;
  f.sum = 12.0;
  f.last = 5.0;
  f.max = 6.0;
  ch->write(&f, 1);
  crease::daemon::FigureWatch watch(host.ports());
  const auto taken = crease::daemon::figure_summaries(watch.take());
  const crease::Figure safe{};
  ch->write(&safe, 2);  // the stop: the output's safe value
  char tmpl[] = "/tmp/crease-report-XXXXXX";
  const std::filesystem::path dir = mkdtemp(tmpl);
  auto count_in = [&](const std::vector<crease::report::FigureSummary>* figures) {
    crease::daemon::write_reports(host, crease::daemon::RunFacts{}, dir.string(), figures);
    std::ifstream in(dir / "report.json");
    const auto j = nlohmann::json::parse(in);
    REQUIRE(j["figures"].size() == 1);
    return j["figures"][0]["count"].get<std::uint64_t>();
  };
  CHECK(count_in(&taken) == 3);
  CHECK(count_in(nullptr) == 0);  // the ports now: what the report showed before
  std::filesystem::remove_all(dir);
}
