#include "drivers/can/mock_can_bus.h"

#include <doctest/doctest.h>
#include <linux/can/error.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "drivers/can/mock_can_broker.h"
#include "rt/alloc_guard.h"

using namespace crease::drivers;

namespace {
std::string unique_bus(const char* tag) {
  static int n = 0;
  return std::string(tag) + "-" + std::to_string(::getpid()) + "-" + std::to_string(++n);
}

// Waits up to timeout_ms for one data frame (error frames are returned too).
RecvResult recv_wait(CanBus& bus, RxFrame& out, int timeout_ms = 1000) {
  for (;;) {
    const RecvResult r = bus.try_receive(out);
    if (r != RecvResult::empty) return r;
    pollfd p{bus.fd(), POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) <= 0) return RecvResult::empty;
  }
}

std::vector<std::uint32_t> drain_ids(CanBus& bus, int quiet_ms = 50) {
  std::vector<std::uint32_t> ids;
  RxFrame rx;
  while (recv_wait(bus, rx, quiet_ms) == RecvResult::frame) ids.push_back(rx.frame.id());
  return ids;
}

CanFrame frame_with_id(std::uint32_t id) {
  const std::uint8_t b[4] = {static_cast<std::uint8_t>(id), 0xA5, 0x5A, 0x01};
  return CanFrame::fd(id, b);
}

MockCanBusConfig node(const std::string& bus, std::uint32_t id, std::uint32_t bps = 0) {
  return {bus, id, bps, bps ? 5'000'000u : 0u};
}

void wait_nodes(const MockCanBroker& b, int n) {
  for (int i = 0; i < 200 && b.connected_nodes() < n; ++i) ::usleep(2000);
  REQUIRE(b.connected_nodes() == n);
}
}  // namespace

TEST_CASE("frames travel between nodes in one process, not back to the sender") {
  const std::string name = unique_bus("inproc");
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a(node(name, 1)), b(node(name, 2)), c(node(name, 3));
  wait_nodes(broker, 3);
  std::uint8_t payload[64];
  for (int i = 0; i < 64; ++i) payload[i] = static_cast<std::uint8_t>(i * 3);
  const CanFrame f = CanFrame::fd(0x181, payload);
  REQUIRE(a.send(f) == SendResult::ok);
  RxFrame rx;
  REQUIRE(recv_wait(b, rx) == RecvResult::frame);
  CHECK(rx.frame == f);
  CHECK(rx.timestamp_ns > 0);
  REQUIRE(recv_wait(c, rx) == RecvResult::frame);
  CHECK(rx.frame == f);
  CHECK(recv_wait(a, rx, 30) == RecvResult::empty);
  CHECK(a.counters().tx_frames == 1);
  CHECK(b.counters().rx_frames == 1);
}

TEST_CASE("connecting to a bus nobody serves throws, naming the bus") {
  CHECK_THROWS_WITH_AS(MockCanBus(node("no-such-bus-xyz", 1)), doctest::Contains("no-such-bus-xyz"),
                       std::runtime_error);
}

TEST_CASE("a full transmit queue gives no_buffers (ENOBUFS emulation) and drains at the bitrate") {
  const std::string name = unique_bus("enobufs");
  MockCanBroker broker({name, 125'000, 125'000, false});
  MockCanBus a(node(name, 1, 125'000)), b(node(name, 2, 125'000));
  wait_nodes(broker, 2);
  const std::uint8_t b8[8] = {};
  const CanFrame f = CanFrame::classic(0x100, b8);  // ~1 ms each at 125 kbit/s
  int ok = 0;
  SendResult last = SendResult::ok;
  for (int i = 0; i < 20; ++i) {
    last = a.send(f);
    if (last != SendResult::ok) break;
    ++ok;
  }
  CHECK(ok == MockCanBus::kTxQueueLen);
  CHECK(last == SendResult::no_buffers);
  CHECK(a.counters().tx_no_buffers == 1);
  ::usleep(3000);  // a few frames have left the queue
  CHECK(a.send(f) == SendResult::ok);
  // Bus-load model: receive timestamps are one frame time apart.
  RxFrame r1, r2;
  REQUIRE(recv_wait(b, r1) == RecvResult::frame);
  REQUIRE(recv_wait(b, r2) == RecvResult::frame);
  const std::int64_t dt = r2.timestamp_ns - r1.timestamp_ns;
  CHECK(dt == can_frame_time_ns(f, 125'000, 125'000));
}

TEST_CASE("nodes in separate processes share a bus") {
  const std::string name = unique_bus("xproc");
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    // Echo server: answers every frame with id + 1. Retries until the broker exists.
    for (int attempt = 0; attempt < 500; ++attempt) {
      try {
        MockCanBus bus(node(name, 7));
        RxFrame rx;
        int echoed = 0;
        while (echoed < 100 && recv_wait(bus, rx, 2000) == RecvResult::frame) {
          CanFrame out = rx.frame;
          out.can_id = rx.frame.id() + 1;
          while (bus.send(out) != SendResult::ok) ::usleep(100);
          ++echoed;
        }
        ::_exit(echoed == 100 ? 0 : 3);
      } catch (...) {
        ::usleep(2000);
      }
    }
    ::_exit(2);
  }
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a(node(name, 1));
  wait_nodes(broker, 2);
  int good = 0;
  for (std::uint32_t i = 0; i < 100; ++i) {
    REQUIRE(a.send(frame_with_id(0x200 + 2 * i)) == SendResult::ok);
    RxFrame rx;
    REQUIRE(recv_wait(a, rx) == RecvResult::frame);
    if (rx.frame.id() == 0x201 + 2 * i && rx.frame.data[1] == 0xA5) ++good;
  }
  CHECK(good == 100);
  int status = 0;
  ::waitpid(child, &status, 0);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
}

TEST_CASE("seeded faults: drop, duplicate, reorder, corrupt are reproducible") {
  auto run = [](const CanFaultConfig& faults) {
    const std::string name = unique_bus("faults");
    MockCanBroker broker({name, 0, 0, false});
    broker.set_faults(faults);
    MockCanBus a(node(name, 1)), b(node(name, 2));
    wait_nodes(broker, 2);
    for (std::uint32_t i = 0; i < 200; ++i) {
      while (a.send(frame_with_id(i)) != SendResult::ok) ::usleep(50);
      if (i % 16 == 0) ::usleep(200);
    }
    std::vector<std::uint32_t> got;
    RxFrame rx;
    while (recv_wait(b, rx, 100) == RecvResult::frame) {
      got.push_back(rx.frame.id());
      got.push_back(rx.frame.data[1]);
    }
    return got;
  };
  CanFaultConfig drop;
  drop.seed = 42;
  drop.drop = 0.3;
  const auto d1 = run(drop), d2 = run(drop);
  CHECK(d1 == d2);
  CHECK(d1.size() / 2 < 180);
  CHECK(d1.size() / 2 > 100);

  CanFaultConfig dup;
  dup.duplicate = 0.2;
  CHECK(run(dup).size() / 2 > 210);

  CanFaultConfig reo;
  reo.reorder = 0.2;
  const auto r = run(reo);
  REQUIRE(r.size() == 400);
  int inversions = 0;
  for (std::size_t i = 2; i < r.size(); i += 2) inversions += r[i] < r[i - 2] ? 1 : 0;
  CHECK(inversions > 5);

  CanFaultConfig cor;
  cor.corrupt = 0.5;
  const auto c = run(cor);
  REQUIRE(c.size() == 400);
  int changed = 0;
  for (std::size_t i = 1; i < c.size(); i += 2) changed += c[i] != 0xA5 ? 1 : 0;
  CHECK(changed > 5);  // some flips land in byte 1
}

TEST_CASE("delay fault delivers late; error frames reach every node") {
  const std::string name = unique_bus("delay");
  MockCanBroker broker({name, 0, 0, false});
  CanFaultConfig f;
  f.delay = 1.0;
  f.delay_ns = 20'000'000;
  broker.set_faults(f);
  MockCanBus a(node(name, 1)), b(node(name, 2));
  wait_nodes(broker, 2);
  REQUIRE(a.send(frame_with_id(5)) == SendResult::ok);
  RxFrame rx;
  CHECK(recv_wait(b, rx, 5) == RecvResult::empty);
  CHECK(recv_wait(b, rx, 500) == RecvResult::frame);

  broker.set_faults({});
  broker.inject_error_frame(make_error_frame_for_state(BusState::error_passive));
  REQUIRE(recv_wait(a, rx) == RecvResult::error_frame);
  CHECK(a.state() == BusState::error_passive);
  REQUIRE(recv_wait(b, rx) == RecvResult::error_frame);
  CHECK(b.counters().rx_error_frames == 1);
}

TEST_CASE("bus-off holds until restart; a silent node's frames vanish") {
  const std::string name = unique_bus("busoff");
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a(node(name, 1)), b(node(name, 2));
  wait_nodes(broker, 2);
  broker.force_bus_off(1);
  RxFrame rx;
  REQUIRE(recv_wait(a, rx) == RecvResult::error_frame);
  CHECK(a.state() == BusState::bus_off);
  CHECK(a.send(frame_with_id(1)) == SendResult::bus_off);
  CHECK(a.counters().bus_off_events == 1);
  a.restart();
  CHECK(a.state() == BusState::error_active);
  REQUIRE(recv_wait(a, rx) == RecvResult::error_frame);  // CAN_ERR_RESTARTED
  CHECK(a.state() == BusState::error_active);
  REQUIRE(a.send(frame_with_id(2)) == SendResult::ok);
  REQUIRE(recv_wait(b, rx) == RecvResult::frame);
  CHECK(rx.frame.id() == 2);

  broker.set_silent(1, true);
  REQUIRE(a.send(frame_with_id(3)) == SendResult::ok);  // the node believes it sent
  CHECK(recv_wait(b, rx, 50) == RecvResult::empty);
  broker.set_silent(1, false);
  REQUIRE(a.send(frame_with_id(4)) == SendResult::ok);
  REQUIRE(recv_wait(b, rx) == RecvResult::frame);
  CHECK(rx.frame.id() == 4);
}

TEST_CASE("send and try_receive do not allocate") {
  const std::string name = unique_bus("alloc");
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a(node(name, 1)), b(node(name, 2));
  wait_nodes(broker, 2);
  REQUIRE(crease::rt::alloc_hooks_installed());
  {
    crease::rt::ScopedRtMark mark;
    const auto before = crease::rt::rt_allocation_count();
    auto* p = new int(1);  // the counter must see this one
    CHECK(crease::rt::rt_allocation_count() == before + 1);
    delete p;
  }
  RxFrame rx;
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark mark;
    for (int i = 0; i < 100; ++i) {
      (void)a.send(frame_with_id(static_cast<std::uint32_t>(i)));
      (void)b.try_receive(rx);
    }
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  CHECK(drain_ids(b).size() + b.counters().rx_frames >= 1);
}

TEST_CASE("back-pressure: a fast reader gets every frame in order; a node that never reads stalls nobody") {
  const std::string name = unique_bus("bp");
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a(node(name, 1)), b(node(name, 2)), idle(node(name, 3));
  wait_nodes(broker, 3);
  constexpr std::uint32_t kFrames = 30'000;
  std::uint32_t sent = 0, got = 0, out_of_order = 0;
  RxFrame rx;
  while (got < kFrames) {
    while (sent < kFrames) {
      std::uint8_t d[4];
      std::memcpy(d, &sent, 4);
      if (a.send(CanFrame::classic(0x10, d)) != SendResult::ok) break;  // back-pressure
      ++sent;
    }
    const RecvResult r = recv_wait(b, rx, 2000);
    REQUIRE(r == RecvResult::frame);
    std::uint32_t v;
    std::memcpy(&v, rx.frame.data, 4);
    out_of_order += v != got ? 1 : 0;
    ++got;
  }
  CHECK(out_of_order == 0);
  CHECK(broker.stats().rx_overflow > 0);  // only the idle node lost frames
  CHECK(a.counters().tx_no_buffers > 0);  // the sender felt the back-pressure
}
