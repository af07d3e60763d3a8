#include <doctest/doctest.h>

#include <cstdio>

#include "../host/host_test_support.h"
#include "hil_rig.h"

using namespace crease::drivers;
using crease::drivers::testing::Rig;

TEST_CASE("seeded fault mix: acks or failures within 2 cycles, nothing stale marked fresh, safe within 3 cycles") {
  Rig rig;
  REQUIRE(rig.all_spawned());
  for (int i = 0; i < 500 && !rig.all_connected(); ++i) ::usleep(2000);
  REQUIRE(rig.all_connected());
  CanFaultConfig f;
  f.drop = 0.005;
  f.corrupt = 0.005;
  f.duplicate = 0.005;
  f.reorder = 0.005;
  f.delay = 0.002;
  f.delay_ns = 3'000'000;
  f.error_frame = 0.001;
  for (int i = 0; i < Rig::kDevices; ++i) {
    f.seed = 1000 + static_cast<std::uint64_t>(i);
    rig.brokers[static_cast<std::size_t>(i)]->set_faults(f);
  }
  hand::Command hc;
  hc.flags = hand::kCmdEnable;
  hand::Stiffness hs;
  arm::Command ac;
  std::uint8_t sync_sent[4] = {};
  long stale_marked_fresh = 0;
  constexpr int kCycles = 5000, kSilentFrom = 2000, kSilentTo = 2300, kBusOffAt = 3000;
  int hand_safe_at = -1, arm_safe_at = -1;
  bool hand_recovered = false, arm_recovered = false;
  long left_fault_cycles = 0;  // the left hand's link after its bus-off: cycles in fault
  crease::drivers::testing::Ticker tick;
  for (int cyc = 0; cyc < kCycles; ++cyc) {
    if (cyc == kSilentFrom) {
      rig.brokers[0]->set_silent(1, true);   // right hand falls silent
      rig.brokers[2]->set_silent(10, true);  // right arm too
    }
    if (cyc == kSilentTo) {
      rig.brokers[0]->set_silent(1, false);
      rig.brokers[2]->set_silent(10, false);
    }
    if (cyc == kBusOffAt) rig.brokers[1]->force_bus_off(100);  // our node on the left hand's bus
    const std::int64_t now = tick.wait();
    for (int h = 0; h < 2; ++h) {
      rig.hands[h]->read_from_rt(now);
      const auto& r = rig.hands[h]->reading();
      if (r.fresh && r.status.sync_counter != sync_sent[h]) ++stale_marked_fresh;
    }
    for (int a = 0; a < 2; ++a) {
      rig.arms[a]->read_from_rt(now);
      const auto& r = rig.arms[a]->reading();
      if (r.fresh && r.status.sync_counter != sync_sent[2 + a]) ++stale_marked_fresh;
    }
    for (int h = 0; h < 2; ++h) {
      rig.hands[h]->write_from_rt(hc, hs, now);
      sync_sent[h] = rig.hands[h]->last_sync_sent();
    }
    for (int a = 0; a < 2; ++a) {
      rig.arms[a]->write_from_rt(ac, now);
      sync_sent[2 + a] = rig.arms[a]->last_sync_sent();
    }
    if (cyc >= kSilentFrom && cyc < kSilentTo) {
      if (hand_safe_at < 0 && rig.hands[0]->commanding_safe_state()) hand_safe_at = cyc - kSilentFrom + 1;
      if (arm_safe_at < 0 && rig.arms[0]->commanding_safe_state()) arm_safe_at = cyc - kSilentFrom + 1;
    }
    if (cyc >= kBusOffAt + 1000)
      left_fault_cycles += rig.hands[1]->health() == LinkHealth::fault ? 1 : 0;
    if (cyc > kSilentTo + 200 && cyc < kBusOffAt) {
      hand_recovered = hand_recovered || rig.hands[0]->health() == LinkHealth::ok;
      arm_recovered = arm_recovered || rig.arms[0]->health() == LinkHealth::ok;
    }
  }
  CHECK(stale_marked_fresh == 0);
  CHECK(hand_safe_at >= 1);
  CHECK(hand_safe_at <= 3);
  CHECK(arm_safe_at >= 1);
  CHECK(arm_safe_at <= 3);
  CHECK(hand_recovered);
  CHECK(arm_recovered);
  CHECK(rig.buses[1]->counters().bus_off_events == 1);
  CHECK(rig.buses[1]->state() != BusState::bus_off);  // restarted by the host
  for (int d = 0; d < 4; ++d) {
    const LinkCounters c = d < 2 ? rig.hands[d]->monitor().counters() : rig.arms[d - 2]->monitor().counters();
    std::printf("device %d: sent %llu acked %llu failed %llu bad_crc %llu stale %llu timeouts %llu recoveries %llu\n", d,
                static_cast<unsigned long long>(c.commands_sent), static_cast<unsigned long long>(c.commands_acked),
                static_cast<unsigned long long>(c.commands_failed), static_cast<unsigned long long>(c.bad_crc),
                static_cast<unsigned long long>(c.stale), static_cast<unsigned long long>(c.timeouts),
                static_cast<unsigned long long>(c.recoveries));
    CHECK(c.commands_acked + c.commands_failed + 2 >= c.commands_sent);
    CHECK(c.commands_failed > 0);  // the faults did bite
  }
  // The link the host restarted after its bus-off runs on (a cycle's health is a snapshot of
  // the machine's load: two late answers make it `fault` for a cycle).
  std::printf("left hand: fault %ld of the last %d cycles\n", left_fault_cycles,
              kCycles - kBusOffAt - 1000);
  CHECK(left_fault_cycles * 2 < kCycles - kBusOffAt - 1000);
  std::uint64_t crc = 0;
  for (int h = 0; h < 2; ++h) crc += rig.hands[h]->monitor().counters().bad_crc;
  for (int a = 0; a < 2; ++a) crc += rig.arms[a]->monitor().counters().bad_crc;
  CHECK(crc > 0);  // corrupted frames were seen and rejected by the CRC
}
