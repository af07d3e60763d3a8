// The command table and the shared argument helpers of creased's control commands (the
// commands end to end: tests/core/daemon/creased_test.cpp and tests/core/control).
#include "core/daemon/commands/commands.h"

#include <doctest/doctest.h>

#include <limits>

#include "core/control/protocol.h"

namespace ctl = crease::control;
using crease::daemon::CommandContext;

namespace {
std::string code_of(auto&& fn) {
  try {
    fn();
  } catch (const ctl::RequestError& e) {
    return e.code() + ": " + e.what();
  }
  return "no error";
}
}  // namespace

TEST_CASE("every command of the protocol has a handler, and nothing else does") {
  for (const std::string& cmd : ctl::known_commands()) {
    CAPTURE(cmd);
    CHECK(static_cast<bool>(crease::daemon::find_command(cmd)));
  }
  CHECK_FALSE(static_cast<bool>(crease::daemon::find_command("sequence")));
  CHECK_FALSE(static_cast<bool>(crease::daemon::find_command("")));
}

TEST_CASE("handlers answer through the context: stop says why, views read the host") {
  crease::PluginHost host({});
  crease::daemon::RunFacts facts;
  std::string reason;
  CommandContext ctx{host, facts, nullptr, [&](const std::string& r) { reason = r; }};
  const auto stop = crease::daemon::find_command("stop");
  CHECK(stop({{"cmd", "stop"}}, ctx) == nlohmann::json{{"stopping", true}});
  CHECK(reason == "creasectl stop");
  CHECK(crease::daemon::find_command("ports")({{"cmd", "ports"}}, ctx) == nlohmann::json::array());
  // A refused host call is a `failed` reply with the host's message.
  CHECK(code_of([&] { crease::daemon::find_command("unload")({{"cmd", "unload"}, {"instance", "x"}}, ctx); }) ==
        "failed: unload: no instance named 'x'");
}

TEST_CASE("param set takes a JSON number only: a string is never read as one") {
  crease::PluginHost host({});
  crease::daemon::RunFacts facts;
  CommandContext ctx{host, facts, nullptr, [](const std::string&) {}};
  const auto param = crease::daemon::find_command("param");
  auto set = [&](nlohmann::json value) {
    return code_of([&] {
      param({{"cmd", "param"}, {"instance", "x"}, {"action", "set"}, {"key", "k"}, {"value", value}}, ctx);
    });
  };
  for (const nlohmann::json& bad : {nlohmann::json("0x10"), nlohmann::json("2.5"), nlohmann::json("fast"),
                                    nlohmann::json(""), nlohmann::json(true),
                                    nlohmann::json(std::numeric_limits<double>::infinity())}) {
    CAPTURE(bad);
    CHECK(set(bad) == "bad_argument: param set: value must be a number");
  }
  // Numbers get as far as the host, which has no such instance.
  CHECK(set(2.5).rfind("failed: ", 0) == 0);
  CHECK(set(3).rfind("failed: ", 0) == 0);
  CHECK(code_of([&] { param({{"cmd", "param"}, {"instance", "x"}, {"action", "reset"}, {"key", "k"}}, ctx); }) ==
        "bad_argument: param: action must be get or set, not 'reset'");
}

TEST_CASE("load: order in the configuration's range, ports an object of strings") {
  crease::PluginHost host({});
  crease::daemon::RunFacts facts;
  CommandContext ctx{host, facts, nullptr, [](const std::string&) {}};
  const auto load = crease::daemon::find_command("load");
  const nlohmann::json base = {{"cmd", "load"}, {"instance", "a"}, {"library", "b"}, {"loop", "c"}, {"order", 1}};
  auto with = [&](const char* key, nlohmann::json v) {
    nlohmann::json r = base;
    r[key] = std::move(v);
    return code_of([&] { load(r, ctx); });
  };
  CHECK(with("order", 3'000'000'000LL) == "bad_argument: load: order must be in [-1000000, 1000000]");
  CHECK(with("ports", nlohmann::json::array({1})) == "bad_argument: load: 'ports' must be an object of strings");
  CHECK(with("ports", {{"out", 1}}) == "bad_argument: load: ports values must be strings");
  CHECK(with("ports", {{"out", "x"}}).rfind("failed: ", 0) == 0);  // as far as the host
}

TEST_CASE("params arguments must be objects and are named after the instance") {
  CHECK_FALSE(crease::daemon::params_argument({{"cmd", "swap"}}, "params", "swap", "counter").has_value());
  CHECK(code_of([] {
          (void)crease::daemon::params_argument({{"params", 3}}, "params", "swap", "counter");
        }) == "bad_argument: swap: 'params' must be an object");
  const auto p = crease::daemon::params_argument({{"params", {{"increment", 500}}}}, "params", "swap", "counter");
  REQUIRE(p.has_value());
  CHECK_THROWS_WITH((void)p->get_in_range<int>("increment", 1, 0, 100),
                    doctest::Contains("counter.params.increment: must be in [0, 100], got 500"));
}
