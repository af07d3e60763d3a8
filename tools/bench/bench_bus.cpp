// crease-bench bus [--rtt N] [--seconds S] [--cycles N]
// Mock CAN bus round trip (through the broker) beside a bare AF_UNIX SOCK_SEQPACKET ping-pong;
// sustained frames/s with loss and reordering counted; pty serial round trip (framed) beside a
// raw byte ping-pong on the same pty; one control cycle of four drivers (2 hands, 2 arms:
// read all, write all) against simulated devices, beside the bare syscall floor, each with its
// share of late round trips; the sensing-to-command lag through the plugin loop (write phase)
// beside a loop of one update per plugin.
// The mock bus moves frames through shared-memory rings served by one broker thread per
// process (drivers/can/mock_reactor.h); the drivers' cycle pays a system call only when that
// thread sleeps, and the count of such wake-ups is printed beside the cycle figure.
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench_registry.h"
#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/host/arm_host.h"
#include "drivers/host/hand_host.h"
#include "drivers/serial/serial_port.h"
#include "drivers/simdevice/device_thread.h"
#include "drivers/simdevice/sim_arm.h"
#include "drivers/simdevice/sense_to_command_tap.h"
#include "drivers/simdevice/sim_hand.h"
#include "core/plugin_host.h"
#include "rt/clock.h"

namespace {
using namespace crease::drivers;
using crease::rt::now_ns;

struct Pct {
  double p50, p99, p999;
};
Pct percentiles(std::vector<double> v) {
  if (v.empty()) return {0, 0, 0};
  std::sort(v.begin(), v.end());
  auto at = [&](double q) { return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))]; };
  return {at(0.50), at(0.99), at(0.999)};
}

// SCHED_FIFO for the calling thread (0: back to SCHED_OTHER); false where not permitted.
bool set_fifo(int prio) {
  sched_param sp{};
  sp.sched_priority = prio;
  return pthread_setschedparam(pthread_self(), prio > 0 ? SCHED_FIFO : SCHED_OTHER, &sp) == 0;
}

void wait_readable(int fd) {
  pollfd p{fd, POLLIN, 0};
  (void)::poll(&p, 1, 1000);
}

std::string bus_name(const char* tag) { return std::string("bench-") + tag + "-" + std::to_string(::getpid()); }

// --- 1. round trip -----------------------------------------------------------------------
std::vector<double> mock_rtt(int n) {
  const std::string name = bus_name("rtt");
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a({name, 1, 0, 0}), b({name, 2, 0, 0});
  while (broker.connected_nodes() < 2) ::usleep(1000);
  std::atomic<bool> stop{false};
  std::thread echo([&] {
    RxFrame rx;
    while (!stop.load(std::memory_order_relaxed)) {
      if (b.try_receive(rx) == RecvResult::frame) {
        rx.frame.can_id += 1;
        while (b.send(rx.frame) != SendResult::ok) {
        }
      } else {
        wait_readable(b.fd());
      }
    }
  });
  std::vector<double> us;
  us.reserve(static_cast<std::size_t>(n));
  std::uint8_t payload[64] = {};
  for (int i = 0; i < n + 200; ++i) {
    std::memcpy(payload, &i, sizeof(i));
    const CanFrame f = CanFrame::fd(0x100, payload);
    const std::int64_t t0 = now_ns();
    while (a.send(f) != SendResult::ok) {
    }
    RxFrame rx;
    for (;;) {
      const RecvResult r = a.try_receive(rx);
      if (r == RecvResult::frame) break;
      wait_readable(a.fd());
    }
    if (i >= 200) us.push_back(static_cast<double>(now_ns() - t0) * 1e-3);
  }
  stop = true;
  CanFrame wake = CanFrame::classic(0x7FF, {});
  (void)a.send(wake);
  echo.join();
  return us;
}

std::vector<double> socketpair_rtt(int n) {
  int sv[2];
  ::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv);
  std::thread echo([&] {
    CanFrame f;
    for (;;) {
      const ssize_t r = ::recv(sv[1], &f, sizeof(f), 0);
      if (r <= 0 || f.can_id == 0x7FF) break;
      (void)!::send(sv[1], &f, sizeof(f), 0);
    }
  });
  std::vector<double> us;
  CanFrame f;
  for (int i = 0; i < n + 200; ++i) {
    f.can_id = 0x100;
    const std::int64_t t0 = now_ns();
    (void)!::send(sv[0], &f, sizeof(f), 0);
    (void)!::recv(sv[0], &f, sizeof(f), 0);
    if (i >= 200) us.push_back(static_cast<double>(now_ns() - t0) * 1e-3);
  }
  f.can_id = 0x7FF;
  (void)!::send(sv[0], &f, sizeof(f), 0);
  echo.join();
  ::close(sv[0]);
  ::close(sv[1]);
  return us;
}

// --- 2. sustained throughput ---------------------------------------------------------------
struct Throughput {
  double fps;
  std::uint64_t sent, received, lost, reordered;
};
Throughput throughput(double seconds) {
  const std::string name = bus_name("fps");
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus tx({name, 1, 0, 0}), rx({name, 2, 0, 0});
  while (broker.connected_nodes() < 2) ::usleep(1000);
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> sent{0};
  std::uint64_t received = 0, reordered = 0, expected = 0, lost = 0;
  std::thread sender([&] {
    std::uint8_t b[8] = {};
    const std::int64_t end = now_ns() + static_cast<std::int64_t>(seconds * 1e9);
    std::uint64_t i = 0;
    while (now_ns() < end) {
      for (int k = 0; k < 64; ++k, ++i) {
        std::memcpy(b, &i, 8);
        const CanFrame f = CanFrame::classic(0x123, b);
        while (tx.send(f) != SendResult::ok) std::this_thread::yield();  // back-pressure, not loss
      }
    }
    sent = i;
    done = true;
  });
  const std::int64_t t0 = now_ns();
  RxFrame r;
  std::int64_t last_rx = t0;
  for (;;) {
    const RecvResult res = rx.try_receive(r);
    if (res == RecvResult::frame) {
      std::uint64_t v;
      std::memcpy(&v, r.frame.data, 8);
      if (v < expected) ++reordered;
      else {
        lost += v - expected;
        expected = v + 1;
      }
      ++received;
      last_rx = now_ns();
      continue;
    }
    if (done.load() && received + lost >= sent.load()) break;
    if (done.load() && now_ns() - last_rx > 500'000'000) break;
    wait_readable(rx.fd());
  }
  sender.join();
  const double dt = static_cast<double>(last_rx - t0) * 1e-9;
  const std::uint64_t s = sent.load();
  lost = s > received ? s - received : 0;
  return {static_cast<double>(received) / dt, s, received, lost, reordered};
}

// --- 3. serial round trip --------------------------------------------------------------------
std::vector<double> serial_rtt(int n, bool framed) {
  PtyPair pty;
  SerialPort port({pty.slave_path(), 1'000'000, false});
  std::atomic<bool> stop{false};
  std::thread echo([&] {
    SerialLink dev(pty.master_fd());
    SerialFrame f;
    std::uint8_t raw[256];
    while (!stop.load(std::memory_order_relaxed)) {
      if (framed) {
        if (dev.poll_from_rt(f)) {
          (void)dev.send_from_rt(f.type, f.bytes());
          continue;
        }
      } else {
        const ssize_t k = ::read(pty.master_fd(), raw, sizeof(raw));
        if (k > 0) {
          (void)!::write(pty.master_fd(), raw, static_cast<std::size_t>(k));
          continue;
        }
      }
      wait_readable(pty.master_fd());
    }
  });
  SerialLink host(port.fd());
  std::vector<double> us;
  std::uint8_t payload[16] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16};
  std::uint8_t raw[64];
  for (int i = 0; i < n + 100; ++i) {
    const std::int64_t t0 = now_ns();
    if (framed) {
      (void)host.send_from_rt(1, payload);
      SerialFrame f;
      while (!host.poll_from_rt(f)) wait_readable(port.fd());
    } else {
      (void)!::write(port.fd(), payload, sizeof(payload));
      std::size_t got = 0;
      while (got < sizeof(payload)) {
        const long k = port.read_some_from_rt({raw + got, sizeof(raw) - got});
        if (k > 0) got += static_cast<std::size_t>(k);
        else wait_readable(port.fd());
      }
    }
    if (i >= 100) us.push_back(static_cast<double>(now_ns() - t0) * 1e-3);
  }
  stop = true;
  echo.join();
  return us;
}

// --- 4. control cycle of four drivers ----------------------------------------------------------
// Fills late_share: the share of commands not acknowledged within 2 cycles (a late round trip)
// over the measured cycles, the four links together.
std::vector<double> control_cycle(int cycles, double& late_share) {
  std::vector<std::unique_ptr<MockCanBroker>> brokers;
  std::vector<std::unique_ptr<MockCanBus>> host_buses, dev_buses;
  for (int i = 0; i < 4; ++i) {
    const std::string name = bus_name("cyc") + std::to_string(i);
    brokers.push_back(std::make_unique<MockCanBroker>(MockCanBrokerConfig{name, 1'000'000, 5'000'000, false}));
    host_buses.push_back(std::make_unique<MockCanBus>(MockCanBusConfig{name, 100, 1'000'000, 5'000'000}));
    dev_buses.push_back(std::make_unique<MockCanBus>(MockCanBusConfig{name, 1, 1'000'000, 5'000'000}));
  }
  sim::SimHand h0(*dev_buses[0], {.node = 1}), h1(*dev_buses[1], {.node = 2, .pressure_sensors = true});
  sim::SimArm a0(*dev_buses[2], {.node = 10}), a1(*dev_buses[3], {.node = 11});
  sim::DeviceThread t0(dev_buses[0]->fd(), [&](std::int64_t t) { h0.step(t); }, 1, 70);
  sim::DeviceThread t1(dev_buses[1]->fd(), [&](std::int64_t t) { h1.step(t); }, 1, 70);
  sim::DeviceThread t2(dev_buses[2]->fd(), [&](std::int64_t t) { a0.step(t); }, 1, 70);
  sim::DeviceThread t3(dev_buses[3]->fd(), [&](std::int64_t t) { a1.step(t); }, 1, 70);
  const bool fifo = set_fifo(80);
  HandHost hands[2] = {HandHost(*host_buses[0], {.node = 1}), HandHost(*host_buses[1], {.node = 2, .pressure_sensors = true})};
  ArmHost arms[2] = {ArmHost(*host_buses[2], {.node = 10}), ArmHost(*host_buses[3], {.node = 11})};
  hand::Command hc;
  hc.flags = hand::kCmdEnable;
  hand::Stiffness hs;
  arm::Command ac;
  std::vector<double> us;
  auto link_totals = [&](std::uint64_t& sent, std::uint64_t& failed) {
    sent = failed = 0;
    for (auto& h : hands) sent += h.monitor().counters().commands_sent, failed += h.monitor().counters().commands_failed;
    for (auto& a : arms) sent += a.monitor().counters().commands_sent, failed += a.monitor().counters().commands_failed;
  };
  std::uint64_t sent0 = 0, failed0 = 0;
  std::int64_t next = crease::rt::now_ns();
  for (int c = 0; c < cycles + 300; ++c) {
    next += 1'000'000;
    crease::rt::sleep_until_ns(next);
    const std::int64_t t = now_ns();
    if (c == 300) link_totals(sent0, failed0);
    for (auto& h : hands) h.read_from_rt(t);
    for (auto& a : arms) a.read_from_rt(t);
    for (auto& h : hands) h.write_from_rt(hc, hs, t);
    for (auto& a : arms) a.write_from_rt(ac, t);
    if (c >= 300) us.push_back(static_cast<double>(now_ns() - t) * 1e-3);
  }
  std::uint64_t sent1 = 0, failed1 = 0;
  link_totals(sent1, failed1);
  late_share = sent1 > sent0 ? static_cast<double>(failed1 - failed0) / static_cast<double>(sent1 - sent0) : 0.0;
  int ok = 0;
  for (auto& h : hands) ok += h.health() == LinkHealth::ok;
  for (auto& a : arms) ok += a.health() == LinkHealth::ok;
  std::uint64_t wakeups = 0;
  for (auto& b : host_buses) wakeups += b->broker_wakeups();
  std::printf("  control cycle: %d/4 links ok at the end, loop %s, %.2f broker wake-ups per cycle (system calls)\n", ok,
              fifo ? "SCHED_FIFO 80" : "SCHED_OTHER", static_cast<double>(wakeups) / (cycles + 300));
  set_fifo(0);
  return us;
}

// The alternative: the least a socket-based user-space bus (the mock's transport before the
// shared-memory rings) can cost per cycle. Four bare SEQPACKET socketpairs, each with a peer
// thread blocked in poll() (so every send wakes it); per link one recv of a waiting frame and
// one send of two frames.
// late_share: the share of per-link cycles whose peer's answer had not arrived by the next cycle.
std::vector<double> syscall_floor(int cycles, double& late_share) {
  int sv[4][2];
  for (auto& s : sv) ::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK, 0, s);
  std::atomic<bool> stop{false};
  std::vector<std::thread> peers;
  for (auto& s : sv) {
    peers.emplace_back([&stop, fd = s[1]] {
      CanFrame f;
      while (!stop.load()) {
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, 10) <= 0) continue;
        while (::recv(fd, &f, sizeof(f), MSG_DONTWAIT) > 0) {
        }
        (void)!::send(fd, &f, sizeof(f), MSG_DONTWAIT);  // the "status" for the next cycle
      }
    });
  }
  std::vector<double> us;
  CanFrame f[2];
  std::uint64_t late = 0, answers_due = 0;
  std::int64_t next = crease::rt::now_ns();
  for (int c = 0; c < cycles + 100; ++c) {
    next += 1'000'000;
    crease::rt::sleep_until_ns(next);
    const std::int64_t t = now_ns();
    for (auto& s : sv) {
      const bool got = ::recv(s[0], &f[0], sizeof(f[0]), MSG_DONTWAIT) > 0;
      if (c > 100) {
        ++answers_due;
        late += got ? 0 : 1;
      }
    }
    for (auto& s : sv) {
      iovec iov[2] = {{&f[0], sizeof(CanFrame)}, {&f[1], sizeof(CanFrame)}};
      mmsghdr m[2] = {};
      for (int k = 0; k < 2; ++k) {
        m[k].msg_hdr.msg_iov = &iov[k];
        m[k].msg_hdr.msg_iovlen = 1;
      }
      (void)::sendmmsg(s[0], m, 2, MSG_DONTWAIT);
    }
    if (c >= 100) us.push_back(static_cast<double>(now_ns() - t) * 1e-3);
  }
  late_share = answers_due ? static_cast<double>(late) / static_cast<double>(answers_due) : 0.0;
  stop = true;
  for (auto& p : peers) p.join();
  for (auto& s : sv) {
    ::close(s[0]);
    ::close(s[1]);
  }
  return us;
}

// --- 5. sensing to command --------------------------------------------------------------------
// hand_driver and the hand_echo test plugin (a controller that answers every hand_state) in a
// PluginHost 1 kHz loop against a simulated hand whose bus is tapped: the hand sees how many
// cycles old the status behind each command was. Ours: the echo after the driver, the driver
// sending in its write phase. The alternative, what a loop of one update per plugin allows at
// best: the echo before the driver (it works on the state the driver published last cycle).
struct SenseToCommand {
  int ours_lag = 0, alt_lag = 0;
  double ours_lag0_share = 0, alt_lag0_share = 0;
};
void one_sense_to_command(int cycles, int echo_order, int& lag, double& lag0_share) {
  const std::string name = bus_name("stc") + std::to_string(echo_order);
  MockCanBroker broker(MockCanBrokerConfig{name, 1'000'000, 5'000'000, false});
  MockCanBus dev_bus(MockCanBusConfig{name, 1, 1'000'000, 5'000'000});
  sim::SenseToCommandTap tap(dev_bus, 1);
  sim::SimHand hand(tap, {.node = 1});
  sim::DeviceThread dev(dev_bus.fd(), [&](std::int64_t t) { hand.step(t); }, 1, 70);
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"control", 1000.0, 80, -1});
  crease::InstanceSpec drv;
  drv.name = "hand";
  drv.library = "hand_driver";
  drv.loop = "control";
  drv.order = 10;
  drv.params = crease::Params(YAML::Load("{bus: " + name + ", node: 1, timeout_cycles: 100}"), "bench", "hand.params");
  host.add_instance(drv);
  crease::InstanceSpec echo;
  echo.name = "echo";
  echo.library = "crease_test_hand_echo";
  echo.loop = "control";
  echo.order = echo_order;
  host.add_instance(echo);
  host.start();
  auto counted = [&] {
    std::uint64_t n = 0;
    for (int k = 0; k < sim::SenseToCommandTap::kLags; ++k) n += tap.commands_with_lag(k);
    return n;
  };
  for (int i = 0; i < 10 * cycles && counted() < static_cast<std::uint64_t>(cycles); ++i) ::usleep(1000);
  host.stop();
  lag = tap.typical_lag();
  lag0_share = counted() ? static_cast<double>(tap.commands_with_lag(0)) / static_cast<double>(counted()) : 0.0;
}
SenseToCommand sense_to_command(int cycles) {
  SenseToCommand r;
  one_sense_to_command(cycles, 20, r.ours_lag, r.ours_lag0_share);
  one_sense_to_command(cycles, 5, r.alt_lag, r.alt_lag0_share);
  return r;
}

double arg(int argc, char** argv, const char* name, double def) {
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], name) == 0) return std::atof(argv[i + 1]);
  return def;
}

int run_bus(int argc, char** argv) {
  const int n = static_cast<int>(arg(argc, argv, "--rtt", 20000));
  const double seconds = arg(argc, argv, "--seconds", 5);
  const int cycles = static_cast<int>(arg(argc, argv, "--cycles", 3000));

  // Latency parts run under SCHED_FIFO where permitted (threads inherit it, the broker's too),
  // ours and the alternative alike; the throughput part runs under SCHED_OTHER.
  const bool fifo = set_fifo(80);
  std::printf("scheduling: %s\n", fifo ? "SCHED_FIFO 80 for the latency measurements" : "SCHED_OTHER (no permission for SCHED_FIFO)");
  const Pct ours = percentiles(mock_rtt(n));
  const Pct alt = percentiles(socketpair_rtt(n));
  set_fifo(0);
  std::printf("round trip (us)        p50     p99   p99.9\n");
  std::printf("  mock bus (broker) %7.1f %7.1f %7.1f\n", ours.p50, ours.p99, ours.p999);
  std::printf("  bare socketpair   %7.1f %7.1f %7.1f   ratio p99 %.2f\n", alt.p50, alt.p99, alt.p999, ours.p99 / alt.p99);

  const Throughput tp = throughput(seconds);
  std::printf("sustained: %.0f frames/s over %.0f s, sent %llu received %llu lost %llu reordered %llu\n", tp.fps,
              seconds, static_cast<unsigned long long>(tp.sent), static_cast<unsigned long long>(tp.received),
              static_cast<unsigned long long>(tp.lost), static_cast<unsigned long long>(tp.reordered));
  std::printf("  (a real 1 Mbit/s classic bus carries at most ~8,800 8-byte frames/s; the mock runs unpaced here)\n");

  set_fifo(80);
  const Pct sf = percentiles(serial_rtt(n / 4, true));
  const Pct sr = percentiles(serial_rtt(n / 4, false));
  set_fifo(0);
  std::printf("pty round trip (us)    p50     p99   p99.9\n");
  std::printf("  COBS+CRC frames   %7.1f %7.1f %7.1f\n", sf.p50, sf.p99, sf.p999);
  std::printf("  raw bytes         %7.1f %7.1f %7.1f   ratio p99 %.2f\n", sr.p50, sr.p99, sr.p999, sf.p99 / sr.p99);

  double late_ours = 0, late_floor = 0;
  const Pct cy = percentiles(control_cycle(cycles, late_ours));
  set_fifo(80);
  const Pct fl = percentiles(syscall_floor(cycles, late_floor));
  set_fifo(0);
  std::printf("control cycle, 4 drivers (us) p50 p99 p99.9   late round trips\n");
  std::printf("  drivers           %7.1f %7.1f %7.1f   %6.2f %%\n", cy.p50, cy.p99, cy.p999, 100 * late_ours);
  std::printf("  bare socketpairs  %7.1f %7.1f %7.1f   %6.2f %%   ratio p99 %.2f\n", fl.p50, fl.p99, fl.p999,
              100 * late_floor, cy.p99 / fl.p99);
  std::printf("  (late: a command not acknowledged within 2 cycles; for the socketpairs, a peer's answer not\n"
              "   there by the next cycle: both are the machine's scheduling of the device side)\n");

  const SenseToCommand stc = sense_to_command(cycles);
  std::printf("sensing to command through the 1 kHz loop (hand_driver + a controller after it), at the hand:\n");
  std::printf("  write phase (ours)           typical lag %d cycles, %.1f %% of commands at lag 0\n", stc.ours_lag,
              100 * stc.ours_lag0_share);
  std::printf("  one update per plugin        typical lag %d cycles, %.1f %% of commands at lag 0\n", stc.alt_lag,
              100 * stc.alt_lag0_share);
  std::printf("  (without a write phase the best order is the controller before the driver, which then works\n"
              "   on the previous cycle's sensing)\n");
  const bool clean = tp.lost == 0 && tp.reordered == 0;
  std::printf("bus: rtt_p99_us=%.1f frames_per_s=%.0f serial_rtt_p99_us=%.1f cycle_p99_us=%.1f late_rtt_pct=%.2f "
              "late_floor_pct=%.2f sense_to_command_cycles=%d%s\n",
              ours.p99, clean ? tp.fps : 0.0, sf.p99, cy.p99, 100 * late_ours, 100 * late_floor, stc.ours_lag,
              clean ? "" : " (frames lost or reordered!)");
  return clean ? 0 : 1;
}
}  // namespace

CREASE_BENCH(bus, "mock CAN bus and pty serial round trips, throughput, 4-driver control cycle", run_bus);
