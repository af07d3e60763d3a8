#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>

#include "../host/host_test_support.h"
#include "hil_rig.h"

using namespace crease::drivers;
using crease::drivers::testing::Rig;

TEST_CASE("four devices as processes, 10 s at 1 kHz: every command round-trips, nothing stale") {
  Rig rig;
  REQUIRE(rig.all_spawned());
  for (int i = 0; i < 500 && !rig.all_connected(); ++i) ::usleep(2000);
  REQUIRE(rig.all_connected());
  MESSAGE("scheduling: " << (rig.fifo ? "SCHED_FIFO" : "SCHED_OTHER"));

  hand::Command hc[2];
  hand::Stiffness hs;
  for (float& k : hs.stiffness_nm_per_rad) k = 3.0f;
  arm::Command ac[2];
  std::uint8_t sync_sent[4] = {};
  std::uint32_t last_time[4] = {};
  bool seen[4] = {};
  long stale_marked_fresh = 0, fresh_cycles[4] = {}, measured_cycles = 0;
  LinkCounters at_warm[4];
  std::uint16_t acked_seq_at_warm[4] = {};
  constexpr int kWarm = 500, kCycles = 10'000;
  crease::drivers::testing::Ticker tick;
  for (int cyc = 0; cyc < kCycles; ++cyc) {
    const std::int64_t now = tick.wait();
    const float t = static_cast<float>(cyc) * 1e-3f;
    for (int h = 0; h < 2; ++h) {
      rig.hands[h]->read_from_rt(now);
      const auto& r = rig.hands[h]->reading();
      if (r.fresh) {
        // Independent of LinkMonitor: a fresh status answers our last SYNC, time advanced.
        if (r.status.sync_counter != sync_sent[h] || (seen[h] && r.status.device_time_us <= last_time[h])) ++stale_marked_fresh;
        last_time[h] = r.status.device_time_us;
        seen[h] = true;
      }
    }
    for (int a = 0; a < 2; ++a) {
      rig.arms[a]->read_from_rt(now);
      const auto& r = rig.arms[a]->reading();
      if (r.fresh) {
        if (r.status.sync_counter != sync_sent[2 + a] || (seen[2 + a] && r.status.device_time_us <= last_time[2 + a])) ++stale_marked_fresh;
        last_time[2 + a] = r.status.device_time_us;
        seen[2 + a] = true;
      }
    }
    if (cyc == kWarm) {
      for (int h = 0; h < 2; ++h) at_warm[h] = rig.hands[h]->monitor().counters();
      for (int a = 0; a < 2; ++a) at_warm[2 + a] = rig.arms[a]->monitor().counters();
      for (int h = 0; h < 2; ++h) acked_seq_at_warm[h] = rig.hands[h]->monitor().last_acked_seq();
      for (int a = 0; a < 2; ++a)
        acked_seq_at_warm[2 + a] = rig.arms[a]->monitor().last_acked_seq();
    }
    if (cyc > kWarm) {
      ++measured_cycles;
      for (int h = 0; h < 2; ++h) fresh_cycles[h] += rig.hands[h]->reading().fresh ? 1 : 0;
      for (int a = 0; a < 2; ++a) fresh_cycles[2 + a] += rig.arms[a]->reading().fresh ? 1 : 0;
    }
    for (int h = 0; h < 2; ++h) {
      hc[h].flags = hand::kCmdEnable;
      for (int j = 0; j < hand::kJoints; ++j) hc[h].target_rad[j] = 0.3f * std::sin(2.0f * t + 0.1f * static_cast<float>(j));
      rig.hands[h]->write_from_rt(hc[h], hs, now);
      sync_sent[h] = rig.hands[h]->last_sync_sent();
    }
    for (int a = 0; a < 2; ++a) {
      for (int j = 0; j < arm::kJoints; ++j) ac[a].position_rad[j] = 0.2f * std::sin(t + static_cast<float>(j));
      rig.arms[a]->write_from_rt(ac[a], now);
      sync_sent[2 + a] = rig.arms[a]->last_sync_sent();
    }
  }
  CHECK(stale_marked_fresh == 0);
  for (int d = 0; d < 4; ++d) {
    const LinkCounters c = d < 2 ? rig.hands[d]->monitor().counters() : rig.arms[d - 2]->monitor().counters();
    const auto sent = c.commands_sent - at_warm[d].commands_sent;
    const auto acked = c.commands_acked - at_warm[d].commands_acked;
    const auto failed = c.commands_failed - at_warm[d].commands_failed;
    std::printf("device %d: sent %llu acked %llu failed %llu fresh cycles %ld/%ld\n", d,
                static_cast<unsigned long long>(sent), static_cast<unsigned long long>(acked),
                static_cast<unsigned long long>(failed), fresh_cycles[d], measured_cycles);
    CHECK(c.bad_crc == 0);
    CHECK(acked + failed + 2 >= sent);  // every command resolved within 2 cycles
    // The share of late round trips (a late wake-up of one of 5 processes on a shared machine,
    // reported as a failed command, never hidden) and of fresh cycles are figures of the
    // machine's load: crease-bench bus prints them; they are not compared here. What a broken
    // link cannot do: the device applies the commands (the seq its statuses echo advances
    // with ours, late or not) and some statuses answer the SYNC of their cycle.
    std::printf("device %d: late round trips %.2f %%, fresh cycles %.2f %%\n", d,
                sent ? 100.0 * static_cast<double>(failed) / static_cast<double>(sent) : 0.0,
                measured_cycles ? 100.0 * static_cast<double>(fresh_cycles[d]) / static_cast<double>(measured_cycles) : 0.0);
    const LinkMonitor& m = d < 2 ? rig.hands[d]->monitor() : rig.arms[d - 2]->monitor();
    const auto applied = static_cast<std::uint16_t>(m.last_acked_seq() - acked_seq_at_warm[d]);
    std::printf("device %d: seqs applied %u of %llu sent\n", d, static_cast<unsigned>(applied),
                static_cast<unsigned long long>(sent));
    CHECK(applied * 2 > sent);  // 9500 sent: only a device ~5 s behind at the end fails this
    CHECK(fresh_cycles[d] > 0);
  }
  for (const auto& b : rig.brokers) {
    CHECK(b->stats().dropped_fault == 0);
    CHECK(b->stats().rx_overflow == 0);
  }
  CHECK(rig.hands[0]->health() != LinkHealth::fault);
  CHECK(rig.arms[1]->reading().drive == cia402::State::operation_enabled);
}
