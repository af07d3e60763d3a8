// open_bus_from_params: `bus_prefix` puts the bus under a simulated robot's prefix ("auto":
// this process's own), only on a mocked bus; a bus nobody serves names the key.
#include "drivers/host/link_params.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <string>

#include "drivers/can/mock_can_broker.h"
#include "drivers/host/bus_prefix.h"

using namespace crease;
namespace dr = crease::drivers;

namespace {
Params parse(const std::string& yaml) { return Params(YAML::Load(yaml), "sim.yaml", "plugins[3].params"); }
std::string error_of(auto&& fn) {
  try {
    fn();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST_CASE("bus_prefix: auto joins the bus this process's sim_devices serves") {
  dr::MockCanBroker broker({dr::auto_bus_prefix() + "-lp_auto", 0, 0, false});
  const auto bus = dr::open_bus_from_params(parse("{bus_prefix: auto, bus: lp_auto}"));
  REQUIRE(bus);
  CHECK(broker.connected_nodes() == 1);
}

TEST_CASE("a fixed bus_prefix names the bus <prefix>-<bus>; without one, bus is the whole name") {
  const std::string prefix = "lp-" + std::to_string(::getpid());
  dr::MockCanBroker broker({prefix + "-hand_r", 0, 0, false});
  const auto a = dr::open_bus_from_params(parse("{bus_prefix: " + prefix + ", bus: hand_r}"));
  const auto b = dr::open_bus_from_params(parse("{bus: " + prefix + "-hand_r}"));
  CHECK(broker.connected_nodes() == 2);
  // The other daemon's prefix (auto here) does not reach this broker.
  const std::string other = error_of([] { (void)dr::open_bus_from_params(parse("{bus_prefix: auto, bus: hand_r}")); });
  CHECK(other.find("plugins[3].params.bus: ") != std::string::npos);
  CHECK(other.find(dr::auto_bus_prefix() + "-hand_r") != std::string::npos);
  CHECK(other.find("same bus_prefix") != std::string::npos);
}

TEST_CASE("bus_prefix errors name file, line and key") {
  CHECK(error_of([] { (void)dr::open_bus_from_params(parse("bus: x\nbus_prefix: 'a b'")); })
            .find("sim.yaml:2:13: plugins[3].params.bus_prefix: ") == 0);
  CHECK(error_of([] { (void)dr::open_bus_from_params(parse("{bus_kind: socketcan, bus: can0, bus_prefix: auto}")); })
            .find("plugins[3].params.bus_prefix: only for bus_kind: mock") != std::string::npos);
}

TEST_CASE("the link monitor's parameters: defaults, values, and a range error naming the key") {
  const dr::LinkMonitorConfig d = dr::monitor_from_params(parse("{bus: x}"));
  CHECK(d.timeout_cycles == 2);
  CHECK(d.bus_off_grace_cycles == 3);
  CHECK(dr::monitor_from_params(parse("{bus: x, bus_off_grace_cycles: 0}")).bus_off_grace_cycles ==
        0);
  CHECK(error_of([] {
          (void)dr::monitor_from_params(parse("bus: x\nbus_off_grace_cycles: -1"));
        }).find("sim.yaml:2:23: plugins[3].params.bus_off_grace_cycles: ") == 0);
}
