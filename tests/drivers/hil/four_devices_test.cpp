#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "../host/host_test_support.h"
#include "hil_rig.h"

using namespace crease::drivers;
using crease::drivers::testing::Rig;

TEST_CASE("four devices as processes, 10 s at 1 kHz: every command round-trips, nothing stale") {
  Rig rig;
  REQUIRE(rig.all_spawned());
  for (int i = 0; i < 500 && !rig.all_connected(); ++i) ::usleep(2000);
  REQUIRE(rig.all_connected());
  const std::string scheduling =
      std::string("scheduling: ") + (rig.fifo ? "SCHED_FIFO" : "SCHED_OTHER");
  MESSAGE(scheduling);

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
  // The arms' drives: cycles enabled, and each time one left operation_enabled. Two cycles
  // without a fresh status make the link `fault` and the host quick-stops the drive (a late
  // round trip of the shared machine does it ~15 times a second); the host then re-enables it.
  long enabled_cycles[2] = {}, departures[2] = {}, returns[2] = {};
  int left_at[2] = {-1, -1};
  bool was_enabled[2] = {};
  long fault_cycles[4] = {}, fault_run[4] = {}, longest_fault_run[4] = {};
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
      for (int d = 0; d < 4; ++d) {
        const bool fault =
            (d < 2 ? rig.hands[d]->health() : rig.arms[d - 2]->health()) == LinkHealth::fault;
        fault_cycles[d] += fault ? 1 : 0;
        fault_run[d] = fault ? fault_run[d] + 1 : 0;
        if (fault_run[d] > longest_fault_run[d]) longest_fault_run[d] = fault_run[d];
      }
      for (int a = 0; a < 2; ++a) {
        const bool enabled = rig.arms[a]->reading().drive == cia402::State::operation_enabled;
        enabled_cycles[a] += enabled ? 1 : 0;
        if (was_enabled[a] && !enabled) ++departures[a], left_at[a] = cyc;
        if (!was_enabled[a] && enabled && left_at[a] >= 0) ++returns[a];
        was_enabled[a] = enabled;
      }
    } else if (cyc == kWarm) {
      for (int a = 0; a < 2; ++a)
        was_enabled[a] = rig.arms[a]->reading().drive == cia402::State::operation_enabled;
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
    // Two silent cycles make a link `fault` for a cycle or a few (the safe state is commanded);
    // the share and the longest run are the machine's load. A lost link is fault throughout.
    std::printf("device %d: fault %ld/%ld cycles, longest run %ld\n", d, fault_cycles[d],
                measured_cycles, longest_fault_run[d]);
    CHECK(fault_cycles[d] * 2 < measured_cycles);
  }
  for (const auto& b : rig.brokers) {
    CHECK(b->stats().dropped_fault == 0);
    CHECK(b->stats().rx_overflow == 0);
  }
  // The drives run enabled, and a drive that left operation_enabled (the host's quick stop on a
  // silent link, or the device's watchdog on a stall) is enabled again by the host: only a
  // departure in the last 300 cycles may still be recovering when the loop ends.
  for (int a = 0; a < 2; ++a) {
    std::printf(
        "arm %d: enabled %ld/%ld cycles, left operation_enabled %ld times, re-enabled %ld\n", a,
        enabled_cycles[a], measured_cycles, departures[a], returns[a]);
    CHECK(enabled_cycles[a] * 2 > measured_cycles);
    if (was_enabled[a]) {
      CHECK(returns[a] == departures[a]);
    } else {
      CHECK(returns[a] + 1 == departures[a]);
      CHECK(kCycles - left_at[a] <= 300);
    }
  }
}
