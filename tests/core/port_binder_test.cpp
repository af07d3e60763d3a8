#include "core/port_binder.h"

#include <doctest/doctest.h>

namespace {
struct A {
  static constexpr char kPortType[] = "crease.test.A";
  static constexpr std::uint32_t kPortVersion = 3;
  double x;
};
}  // namespace

TEST_CASE("find: a port another instance bound, by the remapped name; nothing for an unbound one") {
  crease::PortRegistry reg;
  crease::detail::OutputFlags flags;
  crease::PortBinder writer(reg, "model", {}, &flags, nullptr);
  (void)writer.latest_output<A>("state_left", A{0.0});
  crease::PortBinder bridge(reg, "bridge", {{"state", "state_left"}}, &flags, nullptr);
  const auto info = bridge.find("state");
  REQUIRE(info.has_value());
  CHECK(info->name == "state_left");
  CHECK(info->type_name == "crease.test.A");
  CHECK(info->type_version == 3);
  CHECK(info->size == sizeof(A));
  CHECK(info->writer == "model");
  CHECK_FALSE(bridge.find("state_left_typo").has_value());
  CHECK(bridge.unused_remaps() == std::vector<std::string>{"state"});  // find() binds nothing
}
