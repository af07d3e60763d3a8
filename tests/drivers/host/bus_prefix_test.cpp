// bus_prefix: "auto" is this process's own prefix, a fixed name is kept, a bad value is a
// configuration error naming the file, line and key.
#include "drivers/host/bus_prefix.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

using namespace crease;
namespace dr = crease::drivers;

namespace {
Params parse(const std::string& yaml) { return Params(YAML::Load(yaml), "sim.yaml", "plugins[2].params"); }
std::string error_of(auto&& fn) {
  try {
    fn();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST_CASE("auto resolves to this process's prefix, the same for every plugin that asks") {
  CHECK(dr::auto_bus_prefix() == "crease-sim-" + std::to_string(::getpid()));
  const auto a = dr::bus_prefix_from_params(parse("bus_prefix: auto"), std::nullopt);
  const auto b = dr::bus_prefix_from_params(parse("{}"), std::string(dr::kAutoBusPrefix));
  REQUIRE(a);
  REQUIRE(b);
  CHECK(*a == dr::auto_bus_prefix());
  CHECK(*a == *b);
  CHECK(dr::prefixed_bus(*a, "hand_r") == dr::auto_bus_prefix() + "-hand_r");
}

TEST_CASE("a fixed prefix is kept; absent with no fallback is no prefix") {
  CHECK(*dr::bus_prefix_from_params(parse("bus_prefix: crease-sim"), std::nullopt) == "crease-sim");
  CHECK(*dr::bus_prefix_from_params(parse("bus_prefix: rig_2.b-7"), std::string("auto")) == "rig_2.b-7");
  CHECK(*dr::bus_prefix_from_params(parse("{}"), std::string("crease-sim")) == "crease-sim");
  CHECK_FALSE(dr::bus_prefix_from_params(parse("{}"), std::nullopt));
}

TEST_CASE("a bad prefix is an error with file:line:column and the key") {
  CHECK(error_of([] { (void)dr::bus_prefix_from_params(parse("node: 1\nbus_prefix: 'my robot'"), std::nullopt); }) ==
        "sim.yaml:2:13: plugins[2].params.bus_prefix: 'my robot': only letters, digits, '.', '_' and '-', or 'auto'");
  CHECK(error_of([] { (void)dr::bus_prefix_from_params(parse("bus_prefix: ''"), std::nullopt); })
            .find("sim.yaml:1:13: plugins[2].params.bus_prefix: must not be empty") == 0);
  CHECK(error_of([] { (void)dr::bus_prefix_from_params(parse("bus_prefix: a/b"), std::nullopt); })
            .find("sim.yaml:1:13: plugins[2].params.bus_prefix: 'a/b'") == 0);
  CHECK(error_of([] { (void)dr::bus_prefix_from_params(parse("bus_prefix: " + std::string(65, 'x')), std::nullopt); })
            .find("plugins[2].params.bus_prefix: at most 64 characters, got 65") != std::string::npos);
  CHECK(error_of([] { (void)dr::bus_prefix_from_params(parse("bus_prefix: [a]"), std::nullopt); })
            .find("plugins[2].params.bus_prefix: expected a string") != std::string::npos);
  CHECK(dr::bus_prefix_problem(std::string(64, 'x')).empty());
}

TEST_CASE("a simulated robot's serial link: <runtime dir>/<prefix>-<name>, names checked") {
  const char* xdg = std::getenv("XDG_RUNTIME_DIR");
  const std::string dir = xdg != nullptr && xdg[0] == '/' ? xdg : "/tmp";
  CHECK(dr::simulated_link_path("crease-sim-42", "tactile_r") == dir + "/crease-sim-42-tactile_r");
  CHECK(dr::valid_link_name("tactile_r"));
  CHECK_FALSE(dr::valid_link_name(""));
  CHECK_FALSE(dr::valid_link_name(".."));
  CHECK_FALSE(dr::valid_link_name("a/b"));
  CHECK_FALSE(dr::valid_link_name(std::string(33, 'a')));
}
