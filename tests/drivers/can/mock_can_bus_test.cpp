#include "drivers/can/mock_can_bus.h"

#include <doctest/doctest.h>
#include <linux/can/error.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <memory>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_reactor.h"
#include "mock_bus_test_support.h"
#include "rt/alloc_guard.h"

using namespace crease::drivers;
using namespace crease::drivers::testing;

namespace {
void require_nodes(const MockCanBroker& b, int n) { REQUIRE(wait_nodes(b, n)); }
}  // namespace

TEST_CASE("frames travel between nodes in one process, not back to the sender") {
  const std::string name = unique_bus("inproc");
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a(node(name, 1)), b(node(name, 2)), c(node(name, 3));
  require_nodes(broker, 3);
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
  // 10 kbit/s (~11 ms a frame) so that a slow or descheduled test thread (sanitizers, a loaded
  // machine) still queues the frames back to back.
  MockCanBroker broker({name, 10'000, 10'000, false});
  MockCanBus a(node(name, 1, 10'000)), b(node(name, 2, 10'000));
  require_nodes(broker, 2);
  const std::uint8_t b8[8] = {};
  const CanFrame f = CanFrame::classic(0x100, b8);
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
  ::usleep(30'000);  // two frames have left the queue
  CHECK(a.send(f) == SendResult::ok);
  // Bus-load model: receive timestamps are one frame time apart.
  RxFrame r1, r2;
  REQUIRE(recv_wait(b, r1) == RecvResult::frame);
  REQUIRE(recv_wait(b, r2) == RecvResult::frame);
  const std::int64_t dt = r2.timestamp_ns - r1.timestamp_ns;
  CHECK(dt == can_frame_time_ns(f, 10'000, 10'000));
}

TEST_CASE("seeded faults: drop, duplicate, reorder, corrupt are reproducible") {
  auto run = [](const CanFaultConfig& faults) {
    const std::string name = unique_bus("faults");
    MockCanBroker broker({name, 0, 0, false});
    broker.set_faults(faults);
    MockCanBus a(node(name, 1)), b(node(name, 2));
    require_nodes(broker, 2);
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
  require_nodes(broker, 2);
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
  require_nodes(broker, 2);
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
  require_nodes(broker, 2);
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
  require_nodes(broker, 3);
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

TEST_CASE("the fd polls readable while frames wait and goes quiet once drained") {
  const std::string name = unique_bus("fd");
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a(node(name, 1)), b(node(name, 2));
  require_nodes(broker, 2);
  for (int round = 0; round < 3; ++round) {
    REQUIRE(a.send(frame_with_id(static_cast<std::uint32_t>(round))) == SendResult::ok);
    pollfd p{b.fd(), POLLIN, 0};
    REQUIRE(::poll(&p, 1, 1000) == 1);
    RxFrame rx;
    REQUIRE(b.try_receive(rx) == RecvResult::frame);
    CHECK(rx.frame.id() == static_cast<std::uint32_t>(round));
    CHECK(b.try_receive(rx) == RecvResult::empty);  // first empty: no system call
    CHECK(b.try_receive(rx) == RecvResult::empty);  // second: re-arms the fd
    CHECK(::poll(&p, 1, 0) == 0);
  }
}

TEST_CASE("no lost wake-ups: ping-pong with pauses that let the broker thread sleep or spin") {
  const std::string name = unique_bus("pingpong");
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a(node(name, 1)), b(node(name, 2));
  require_nodes(broker, 2);
  constexpr int kRounds = 1500;
  std::atomic<int> echoed{0};
  std::thread echo([&] {
    RxFrame rx;
    while (echoed.load() < kRounds) {
      if (recv_wait(b, rx, 2000) != RecvResult::frame) return;
      CanFrame out = rx.frame;
      out.can_id = rx.frame.id() ^ 0x400;
      while (b.send(out) != SendResult::ok) ::usleep(10);
      echoed.fetch_add(1);
    }
  });
  std::mt19937 rng(3);
  int answered = 0;
  const std::uint64_t wakeups_before = a.broker_wakeups();
  for (int i = 0; i < kRounds; ++i) {
    // 0..300 us: sometimes inside the broker's polling window, sometimes after it slept.
    ::usleep(static_cast<useconds_t>(rng() % 300));
    const std::uint32_t id = static_cast<std::uint32_t>(i % 0x400);
    REQUIRE(a.send(frame_with_id(id)) == SendResult::ok);
    RxFrame rx;
    REQUIRE(recv_wait(a, rx, 2000) == RecvResult::frame);
    answered += rx.frame.id() == (id ^ 0x400) ? 1 : 0;
  }
  echo.join();
  CHECK(answered == kRounds);
  CHECK(echoed.load() == kRounds);
  CHECK(a.broker_wakeups() > wakeups_before);  // some sends found the broker asleep
}

TEST_CASE("a send after an idle pause wakes the broker thread; sends right after do not") {
  const std::string name = unique_bus("wake");
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a(node(name, 1)), b(node(name, 2));
  require_nodes(broker, 2);
  ::usleep(20'000);  // the broker's polling window is long over
  const std::uint64_t before = a.broker_wakeups();
  const CanFrame burst[3] = {frame_with_id(1), frame_with_id(2), frame_with_id(3)};
  SendResult last;
  REQUIRE(a.send_batch(burst, &last) == 3);
  CHECK(a.broker_wakeups() == before + 1);  // one wake-up for the whole batch
  CHECK(drain_ids(b) == std::vector<std::uint32_t>{1, 2, 3});
}

TEST_CASE("frames a node sent just before it closed still reach the bus") {
  const std::string name = unique_bus("closing");
  MockCanBroker broker({name, 0, 0, false});
  auto a = std::make_unique<MockCanBus>(node(name, 1));
  MockCanBus b(node(name, 2));
  require_nodes(broker, 2);
  for (int round = 0; round < 20; ++round) {
    ::usleep(2'000);  // let the broker thread fall asleep: the hang-up and the doorbell then
                      // arrive together, and the hang-up is handled first
    const CanFrame burst[3] = {frame_with_id(3 * round + 1), frame_with_id(3 * round + 2), frame_with_id(3 * round + 3)};
    SendResult last;
    REQUIRE(a->send_batch(burst, &last) == 3);
    a.reset();
    const std::vector<std::uint32_t> want{std::uint32_t(3 * round + 1), std::uint32_t(3 * round + 2),
                                          std::uint32_t(3 * round + 3)};
    CHECK(drain_ids(b) == want);
    a = std::make_unique<MockCanBus>(node(name, 1));
    require_nodes(broker, 2);
  }
}

TEST_CASE("brokers of one process share a thread; closing one leaves the others working") {
  const std::string n1 = unique_bus("shared"), n2 = unique_bus("shared"), n3 = unique_bus("shared");
  MockCanBroker b1({n1, 0, 0, false}), b3({n3, 0, 0, false});
  auto b2 = std::make_unique<MockCanBroker>(MockCanBrokerConfig{n2, 0, 0, false});
  MockCanBus a1(node(n1, 1)), c1(node(n1, 2)), a3(node(n3, 1)), c3(node(n3, 2));
  auto a2 = std::make_unique<MockCanBus>(node(n2, 1));
  require_nodes(b1, 2);
  require_nodes(*b2, 1);
  require_nodes(b3, 2);
  REQUIRE(a1.send(frame_with_id(0x11)) == SendResult::ok);
  REQUIRE(a3.send(frame_with_id(0x33)) == SendResult::ok);
  RxFrame rx;
  REQUIRE(recv_wait(c1, rx) == RecvResult::frame);
  CHECK(rx.frame.id() == 0x11);
  REQUIRE(recv_wait(c3, rx) == RecvResult::frame);
  CHECK(rx.frame.id() == 0x33);
  CHECK(recv_wait(c1, rx, 20) == RecvResult::empty);  // buses do not leak into each other
  b2.reset();  // its node sees the hang-up
  CHECK(recv_wait(*a2, rx, 1000) == RecvResult::error);
  CHECK(a2->errno_value() == EPIPE);
  a2.reset();
  REQUIRE(a1.send(frame_with_id(0x12)) == SendResult::ok);
  REQUIRE(recv_wait(c1, rx) == RecvResult::frame);
  CHECK(rx.frame.id() == 0x12);
  REQUIRE(c3.send(frame_with_id(0x34)) == SendResult::ok);
  REQUIRE(recv_wait(a3, rx) == RecvResult::frame);
  CHECK(rx.frame.id() == 0x34);
}

TEST_CASE("burst predictor: locks on a steady period, rides out one late start, re-learns after two") {
  using crease::drivers::mockwire::BurstPredictor;
  auto near = [](std::int64_t a, std::int64_t b) { return a > b - 5'000 && a < b + 5'000; };
  BurstPredictor p;
  CHECK(p.next_ns() == -1);
  CHECK(p.on_activity(1'000'000));
  CHECK(p.on_activity(2'000'000));          // learns 1 ms
  CHECK_FALSE(p.on_activity(2'050'000));    // the devices' answers: same burst
  CHECK(p.on_activity(3'010'000));          // on schedule (within 5 %)
  CHECK(p.next_ns() == -1);                 // not confirmed twice yet
  CHECK(p.on_activity(4'000'000));
  CHECK(near(p.next_ns(), 5'000'000));
  CHECK(p.on_activity(5'200'000));          // a late loop: the schedule stays
  CHECK(near(p.next_ns(), 6'000'000));
  CHECK(p.on_activity(6'001'000));
  CHECK(near(p.next_ns(), 7'000'000));
  CHECK(p.on_activity(7'300'000));          // two starts off the schedule: re-learn
  CHECK(p.on_activity(7'900'000));
  CHECK(p.next_ns() == -1);
  BurstPredictor slow;
  for (std::int64_t t = 1; t <= 6; ++t) slow.on_activity(t * 50'000'000);  // 50 ms apart
  CHECK(slow.next_ns() == -1);
}
