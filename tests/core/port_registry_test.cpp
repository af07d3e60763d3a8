#include "core/port_registry.h"

#include <doctest/doctest.h>

#include "core/errors.h"

namespace {
struct A {
  static constexpr char kPortType[] = "crease.test.A";
  static constexpr std::uint32_t kPortVersion = 1;
  double x;
};
struct A2 {
  static constexpr char kPortType[] = "crease.test.A";
  static constexpr std::uint32_t kPortVersion = 2;
  double x;
};
struct B {
  static constexpr char kPortType[] = "crease.test.B";
  static constexpr std::uint32_t kPortVersion = 1;
  float y;
};
std::string error_of(auto&& fn) {
  try {
    fn();
  } catch (const crease::PortError& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

using crease::port_type_of;

TEST_CASE("writer and readers share one channel") {
  crease::PortRegistry reg;
  auto* w = reg.bind_latest_writer("state", port_type_of<A>(), "model");
  const auto* r = reg.bind_latest_reader("state", port_type_of<A>(), "ctrl");
  CHECK(w == r);
  // The reader may bind first.
  const auto* r2 = reg.bind_latest_reader("later", port_type_of<B>(), "ctrl");
  CHECK(reg.bind_latest_writer("later", port_type_of<B>(), "x") == r2);
  const auto ports = reg.list();
  REQUIRE(ports.size() == 2);
  CHECK(ports[1].name == "state");
  CHECK(ports[1].writer == "model");
  CHECK(ports[1].readers == std::vector<std::string>{"ctrl"});
}

TEST_CASE("mismatches name both ends") {
  crease::PortRegistry reg;
  reg.bind_latest_writer("state", port_type_of<A>(), "model");
  CHECK(error_of([&] { reg.bind_latest_reader("state", port_type_of<B>(), "ctrl"); }) ==
        "port 'state': instance 'ctrl' reads crease.test.B v1 (4 bytes), but instance 'model' writes crease.test.A v1 (8 bytes)");
  CHECK(error_of([&] { reg.bind_latest_reader("state", port_type_of<A2>(), "ctrl"); }).find("crease.test.A v2") !=
        std::string::npos);
  CHECK(error_of([&] { reg.bind_queue_reader("state", port_type_of<A>(), "ctrl", 0); }) ==
        "port 'state': instance 'ctrl' reads it as a queue port, but instance 'model' writes it as a latest port");
  CHECK(error_of([&] { reg.bind_latest_writer("state", port_type_of<A>(), "other"); }) ==
        "port 'state': instance 'other' cannot write it: instance 'model' already does (ports have a single writer)");
  // The same instance name may bind again (a new version during a hot-swap).
  CHECK(error_of([&] { reg.bind_latest_writer("state", port_type_of<A>(), "model"); }) == "no error");
}

TEST_CASE("queues have one reader and a capacity") {
  crease::PortRegistry reg;
  auto* q = reg.bind_queue_writer("events", port_type_of<B>(), "seq", 16);
  CHECK(q->capacity() == 16);
  reg.bind_queue_reader("events", port_type_of<B>(), "model", 0);
  CHECK(error_of([&] { reg.bind_queue_reader("events", port_type_of<B>(), "other", 0); }).find("single reader") !=
        std::string::npos);
  CHECK(error_of([&] { reg.bind_queue_writer("events", port_type_of<B>(), "seq", 64); }).find("asks for a queue of 64") !=
        std::string::npos);
  reg.release("seq");
  CHECK(reg.list()[0].writer.empty());
}
