// The report creased writes lists every port of the host, frame channels too.
#include "core/daemon/report_builder.h"

#include <doctest/doctest.h>

#include "core/report/render.h"

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
