#include "drivers/host/link_monitor.h"

#include <doctest/doctest.h>

#include <initializer_list>

using namespace crease::drivers;

namespace {
// One cycle: optionally a status answering the previous SYNC and acking the previous seq.
void cycle(LinkMonitor& m, std::uint16_t& seq, std::uint8_t& sync, std::uint32_t& t, bool answer,
           bool bus_off = false) {
  m.begin_read();
  if (answer) m.on_status(seq, sync, t += 1000);
  m.end_read(bus_off);
  m.on_sent(++seq, ++sync);
}
}  // namespace

TEST_CASE("health: fault until the first answer, ok when fresh, fault after 2 silent cycles") {
  LinkMonitor m;
  std::uint16_t seq = 0;
  std::uint8_t sync = 0;
  std::uint32_t t = 0;
  CHECK(m.health() == LinkHealth::fault);
  cycle(m, seq, sync, t, false);
  for (int i = 0; i < 10; ++i) cycle(m, seq, sync, t, true);
  CHECK(m.health() == LinkHealth::ok);
  CHECK(m.counters().commands_failed == 0);
  cycle(m, seq, sync, t, false);
  CHECK(m.health() == LinkHealth::degraded);
  cycle(m, seq, sync, t, false);
  CHECK(m.health() == LinkHealth::fault);
  CHECK(m.counters().timeouts == 1);
  CHECK(m.counters().commands_failed >= 1);
  cycle(m, seq, sync, t, true);
  CHECK(m.health() == LinkHealth::ok);
  CHECK(m.counters().recoveries == 2);  // the first answer and this one
}

TEST_CASE("a status answering an older SYNC is stale, never fresh") {
  LinkMonitor m;
  m.begin_read();
  m.end_read(false);
  m.on_sent(1, 1);
  m.begin_read();
  CHECK(m.on_status(1, 1, 100));
  m.end_read(false);
  m.on_sent(2, 2);
  m.begin_read();
  CHECK_FALSE(m.on_status(1, 1, 100));  // a duplicate of last cycle's status
  CHECK_FALSE(m.fresh_this_cycle());
  CHECK(m.on_status(2, 2, 1100));
  CHECK_FALSE(m.on_status(2, 2, 1200));  // a second status in one cycle is not fresh again
  m.end_read(false);
  CHECK(m.counters().stale == 2);
}

TEST_CASE("bad CRCs above the threshold, bus-off and emergencies give fault") {
  LinkMonitorConfig cfg;
  cfg.crc_threshold = 3;
  LinkMonitor m(cfg);
  std::uint16_t seq = 0;
  std::uint8_t sync = 0;
  std::uint32_t t = 0;
  for (int i = 0; i < 3; ++i) cycle(m, seq, sync, t, true);
  m.begin_read();
  m.on_status(seq, sync, t += 1000);
  m.on_bad_crc();
  m.end_read(false);
  CHECK(m.health() == LinkHealth::degraded);
  m.on_sent(++seq, ++sync);
  m.begin_read();
  m.on_status(seq, sync, t += 1000);
  for (int i = 0; i < 3; ++i) m.on_bad_crc();
  m.end_read(false);
  CHECK(m.health() == LinkHealth::fault);
  m.on_sent(++seq, ++sync);
  m.begin_read();
  m.on_status(seq, sync, t += 1000);
  m.end_read(true);
  CHECK(m.health() == LinkHealth::fault);
  m.on_emergency(true);
  CHECK(m.emergency_active());
}

// A bus-off the host restarts at once: degraded while it lasts up to bus_off_grace_cycles (the
// device's silence until its next answer included), a fault past that, and at once with no grace.
TEST_CASE("a bus-off over within its grace is degraded; a longer one, or with no grace, a fault") {
  for (const int off : {1, 2, 3, 4, 10}) {
    for (const int grace : {3, 0}) {
      CAPTURE(off);
      CAPTURE(grace);
      LinkMonitorConfig cfg;
      cfg.bus_off_grace_cycles = grace;
      LinkMonitor m(cfg);
      std::uint16_t seq = 0;
      std::uint8_t sync = 0;
      std::uint32_t t = 0;
      for (int i = 0; i < 5; ++i) cycle(m, seq, sync, t, true);
      REQUIRE(m.health() == LinkHealth::ok);
      bool faulted = false;
      // OFF cycles with the bus off (no answer), then one restarted cycle the device is silent in.
      for (int i = 0; i < off; ++i) {
        cycle(m, seq, sync, t, false, true);
        faulted |= m.health() == LinkHealth::fault;
      }
      cycle(m, seq, sync, t, false);
      faulted |= m.health() == LinkHealth::fault;
      cycle(m, seq, sync, t, true);
      CHECK(m.health() == LinkHealth::ok);
      CHECK(m.counters().bus_offs == 1);
      const bool ridden = grace > 0 && off + 1 <= grace;  // the silent restart cycle counts too
      CHECK(faulted == !ridden);
      CHECK(m.counters().bus_offs_ridden == (ridden ? 1u : 0u));
    }
  }
}
