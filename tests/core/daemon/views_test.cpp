// The JSON views the read-only control commands answer with: every kind of port in `ports`
// (frame channels with their cameras, writer, readers and counters), loops and plugins.
#include "core/daemon/views.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>

#include "core/port.h"
#include "core/port_types/figure.h"

namespace {
struct Sample {
  static constexpr char kPortType[] = "crease.test.Sample";
  static constexpr std::uint32_t kPortVersion = 3;
  double x;
};

const nlohmann::json& port_named(const nlohmann::json& ports, const std::string& name) {
  for (const auto& p : ports)
    if (p["name"] == name) return p;
  FAIL("no port " << name);
  static const nlohmann::json none;
  return none;
}
}  // namespace

TEST_CASE("ports lists latest, queue and frames ports with their ends and counters") {
  crease::PluginHost host({});
  crease::PortRegistry& reg = host.ports();
  const auto type = crease::port_type_of<Sample>();
  crease::rt::LatestChannel* state = reg.bind_latest_writer("state", type, "model");
  (void)reg.bind_latest_reader("state", type, "ctrl");
  const Sample v{1.5};
  state->write(&v, 10);
  crease::rt::QueueChannel* q = reg.bind_queue_writer("events", type, "seq", 4);
  (void)reg.bind_queue_reader("events", type, "model", 0);
  for (int i = 0; i < 6; ++i) (void)q->try_push(&v);  // 4 fit, 2 dropped
  auto images = reg.bind_frames_writer("images", {{"cam0", 4, 2}, {"cam1", 2, 2}}, "cameras");
  auto reader = reg.bind_frames_reader("images", {{"cam0", 4, 2}, {"cam1", 2, 2}}, "vision");
  images->publish(1, 1, 0x3);
  images->publish(2, 2, 0x3);
  images->publish(3, 3, 0x3);
  REQUIRE(reader->acquire_newest() != nullptr);

  const nlohmann::json ports = crease::daemon::ports_view(reg);
  REQUIRE(ports.size() == 3);
  const auto& l = port_named(ports, "state");
  CHECK(l["kind"] == "latest");
  CHECK(l["type"] == "crease.test.Sample");
  CHECK(l["version"] == 3);
  CHECK(l["size"] == sizeof(Sample));
  CHECK(l["writer"] == "model");
  CHECK(l["readers"] == nlohmann::json::array({"ctrl"}));
  CHECK(l["writes"] == 1);
  const auto& e = port_named(ports, "events");
  CHECK(e["kind"] == "queue");
  CHECK(e["capacity"] == 4);
  CHECK(e["pushed"] == 4);
  CHECK(e["dropped"] == 2);
  const auto& f = port_named(ports, "images");
  CHECK(f["kind"] == "frames");
  CHECK(f["type"] == "crease.FrameSet");
  CHECK(f["version"] == 1);
  CHECK(f["size"] == 4 * 2 + 2 * 2);
  CHECK(f["writer"] == "cameras");
  CHECK(f["readers"] == nlohmann::json::array({"vision"}));
  CHECK(f["cameras"] == nlohmann::json::array({"cam0 4x2", "cam1 2x2"}));
  CHECK(f["published"] == 3);
  CHECK(f["consumed"] == 3);
  CHECK(f["overwritten"] == 2);
  CHECK_FALSE(f.contains("writes"));
}

TEST_CASE("status, loops and stats views of a host") {
  crease::PluginHost host({});
  host.add_loop({"control", 1000, 0, -1});
  crease::daemon::RunFacts facts;
  facts.config_file = "sim.yaml";
  facts.start_ns = 1'000'000'000;
  const auto s = crease::daemon::status_view(host, facts, 3'500'000'000);
  CHECK(s["state"] == "running");
  CHECK(s["config"] == "sim.yaml");
  CHECK(s["uptime_s"] == doctest::Approx(2.5));
  CHECK(s["loops"] == 1);
  CHECK(s["plugins"] == 0);
  const auto loops = crease::daemon::loops_view(host);
  REQUIRE(loops.size() == 1);
  CHECK(loops[0]["name"] == "control");
  CHECK(loops[0]["rate_hz"] == 1000.0);
  CHECK(crease::daemon::plugins_view(host).empty());
  const auto stats = crease::daemon::stats_view(host, nullptr);
  CHECK(stats["control"].is_null());
  CHECK(stats["loops"] == loops);
  CHECK(stats["figures"].empty());
  CHECK_FALSE(s.contains("control"));
  // A figure a plugin reports is in stats.
  auto* fig = host.ports().bind_latest_writer("keypoints_per_set", crease::port_type_of<crease::Figure>(), "vision");
  crease::Figure f = crease::Figure::named("vision key-points per frame set", "kp", "frame sets");
  f.count = 2;
  f.sum = 300;
  f.last = 160;
  f.max = 160;
  fig->write(&f, 1);
  const auto figures = crease::daemon::stats_view(host, nullptr)["figures"];
  REQUIRE(figures.size() == 1);
  CHECK(figures[0]["port"] == "keypoints_per_set");
  CHECK(figures[0]["label"] == "vision key-points per frame set");
  CHECK(figures[0]["mean"] == doctest::Approx(150.0));
  CHECK(figures[0]["last"] == doctest::Approx(160.0));
  // With a server: its clients and refusals, busy replies among them.
  struct Nothing : crease::control::RequestHandler {
    nlohmann::json handle(const nlohmann::json&) override { return {}; }
  } nothing;
  crease::control::ServerOptions o;
  o.socket_path = "/tmp/crease_views_test_" + std::to_string(::getpid()) + "/s.sock";
  crease::control::ControlServer server(o, nothing);
  const auto with = crease::daemon::status_view(host, facts, 3'500'000'000, &server);
  CHECK(with["control"] == nlohmann::json{{"clients", 0}, {"busy", 0}, {"refused", 0}});
  CHECK(crease::daemon::stats_view(host, &server)["control"]["busy"] == 0);
  server.stop();
  std::filesystem::remove_all("/tmp/crease_views_test_" + std::to_string(::getpid()));
}
