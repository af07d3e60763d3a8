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

TEST_CASE("frame channels are ports of kind frames: one channel per name, typed by its cameras") {
  using crease::frames::CameraSpec;
  const std::vector<CameraSpec> rig = {{"cam0", 8, 4}, {"cam1", 6, 3}};
  crease::PortRegistry reg;
  CHECK(reg.find_frames("images") == nullptr);
  // The reader may bind first; both ends get the same channel, named like the port.
  auto r = reg.bind_frames_reader("images", rig, "vision");
  auto w = reg.bind_frames_writer("images", rig, "cameras");
  CHECK(r.get() == w.get());
  CHECK(reg.find_frames("images").get() == w.get());
  CHECK(w->name() == "images");
  CHECK(reg.find_latest("images") == nullptr);

  w->publish(1, 1, 0x3);
  w->publish(2, 2, 0x3);  // the first set is replaced unread
  REQUIRE(r->acquire_newest() != nullptr);
  const auto ports = reg.list();
  REQUIRE(ports.size() == 1);
  const crease::PortInfo& p = ports[0];
  CHECK(p.kind == crease::PortKind::frames);
  CHECK(std::string(crease::to_string(p.kind)) == "frames");
  CHECK(p.type_name == "crease.FrameSet");
  CHECK(p.type_version == 1);
  CHECK(p.size == 8 * 4 + 6 * 3);
  CHECK(p.writer == "cameras");
  CHECK(p.readers == std::vector<std::string>{"vision"});
  CHECK(p.cameras == std::vector<std::string>{"cam0 8x4", "cam1 6x3"});
  CHECK(p.sequence == 2);
  CHECK(p.consumed == 2);
  CHECK(p.overwritten == 1);

  // A hot swap rebinds under the same instance name; release forgets the roles, the channel stays.
  CHECK(error_of([&] { (void)reg.bind_frames_writer("images", rig, "cameras"); }) == "no error");
  reg.release("vision");
  CHECK(reg.list()[0].readers.empty());
  CHECK(reg.find_frames("images").get() == w.get());
}

TEST_CASE("frame channel mismatches name both ends and the camera") {
  using crease::frames::CameraSpec;
  const std::vector<CameraSpec> rig = {{"cam0", 8, 4}, {"cam1", 6, 3}};
  crease::PortRegistry reg;
  (void)reg.bind_frames_writer("images", rig, "cameras");
  auto other = rig;
  other[1].width = 7;
  CHECK(error_of([&] { (void)reg.bind_frames_reader("images", other, "vision"); }) ==
        "port 'images': instance 'vision' reads camera 1 as 'cam1' 7x3, but instance 'cameras' writes it as "
        "'cam1' 6x3");
  CHECK(error_of([&] { (void)reg.bind_frames_reader("images", {{"cam0", 8, 4}}, "vision"); }) ==
        "port 'images': instance 'vision' reads 1 cameras, but instance 'cameras' writes 2");
  CHECK(error_of([&] { (void)reg.bind_frames_writer("images", rig, "replay"); }).find("single writer") !=
        std::string::npos);
  (void)reg.bind_frames_reader("images", rig, "vision");
  CHECK(error_of([&] { (void)reg.bind_frames_reader("images", rig, "vision2"); }) ==
        "port 'images': instance 'vision2' cannot read it: instance 'vision' already does (frame channels have a "
        "single reader)");
  // One namespace for every kind of port.
  reg.bind_latest_writer("state", port_type_of<A>(), "model");
  CHECK(error_of([&] { (void)reg.bind_frames_reader("state", rig, "vision"); }) ==
        "port 'state': instance 'vision' reads it as a frames port, but instance 'model' writes it as a latest port");
  CHECK(error_of([&] { reg.bind_latest_reader("images", port_type_of<A>(), "ctrl"); }) ==
        "port 'images': instance 'ctrl' reads it as a latest port, but instance 'cameras' writes it as a frames port");
  // A rig the channel cannot hold is refused before any port exists.
  CHECK_THROWS_WITH_AS((void)reg.bind_frames_writer("bad", {{"a", 0, 4}}, "cameras"),
                       doctest::Contains("'a' has size 0x4"), crease::ConfigError);
  CHECK(reg.list().size() == 2);
}
