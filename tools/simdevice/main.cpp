// crease-simdevice: runs one simulated device (or a mock bus broker) as its own process.
//   crease-simdevice broker  --bus NAME [--bitrate 1000000] [--data-bitrate 5000000] [--pace]
//                            [--seed S] [--drop P] [--corrupt P] [--duplicate P] [--reorder P]
//                            [--delay P] [--delay-ms MS] [--error-frames P]
//   crease-simdevice hand    --bus NAME --node N [--pressure] [--bitrate ..] [--data-bitrate ..]
//   crease-simdevice arm     --bus NAME --node N
//   crease-simdevice tactile             (creates a pty, prints "pty: /dev/pts/N", serves it)
//   crease-simdevice record  --bus NAME --out FILE.log [--node N]   (candump -L log of the bus)
//   crease-simdevice replay  --bus NAME --in FILE.log [--speed X]   (X <= 0: as fast as the bus takes)
//   crease-simdevice socketcand --bus NAME [--listen 127.0.0.1:PORT] [--interface can0] [--node N]
//                            (a socketcand server for the bus; PORT 0: any, printed as "socketcand: HOST:PORT")
//   common: [--group G] (members of group G may use the bus too; default $CREASE_CAN_GROUP)
//           [--seconds S] (default: until SIGINT/SIGTERM) [--silent-after S --silent-for S]
//           [--fifo PRIO] (run under SCHED_FIFO where permitted, like a device's firmware)
// Exit status 0 on a clean stop; 2 on a usage error (the message names the option).
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "drivers/can/mock_can_broker.h"
#include "drivers/can/candump_log.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/can/recording_can_bus.h"
#include "drivers/can/socketcand_bridge.h"
#include "drivers/serial/serial_port.h"
#include "drivers/simdevice/sim_arm.h"
#include "drivers/simdevice/sim_hand.h"
#include "rt/clock.h"
#include "drivers/simdevice/sim_tactile.h"

namespace {
using namespace crease::drivers;

volatile sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

struct Args {
  std::string mode;
  std::map<std::string, std::string> opts;
  bool has(const std::string& k) const { return opts.count(k) != 0; }
  std::string str(const std::string& k, const std::string& def = "") const {
    auto it = opts.find(k);
    return it == opts.end() ? def : it->second;
  }
  double num(const std::string& k, double def) const {
    auto it = opts.find(k);
    if (it == opts.end()) return def;
    char* end = nullptr;
    const double v = std::strtod(it->second.c_str(), &end);
    if (end == it->second.c_str() || *end != '\0') {
      throw std::invalid_argument("option --" + k + ": '" + it->second + "' is not a number");
    }
    return v;
  }
};

Args parse(int argc, char** argv) {
  if (argc < 2) throw std::invalid_argument("missing mode (broker, hand, arm, tactile, record, replay, socketcand)");
  Args a;
  a.mode = argv[1];
  for (int i = 2; i < argc; ++i) {
    std::string k = argv[i];
    if (k.rfind("--", 0) != 0) throw std::invalid_argument("unexpected argument '" + k + "'");
    k = k.substr(2);
    const bool flag = k == "pressure" || k == "pace";
    if (flag) {
      a.opts[k] = "1";
    } else {
      if (i + 1 >= argc) throw std::invalid_argument("option --" + k + " needs a value");
      a.opts[k] = argv[++i];
    }
  }
  return a;
}

// Runs step() until stopped; toggles silence on the schedule given by --silent-after/--silent-for.
int serve(const Args& a, int fd, const std::function<void(std::int64_t)>& step,
          const std::function<void(bool)>& set_silent) {
  const std::int64_t t0 = crease::rt::now_ns();
  const double seconds = a.num("seconds", 0);
  const double silent_after = a.num("silent-after", -1), silent_for = a.num("silent-for", 0);
  bool silent = false;
  while (!g_stop) {
    pollfd p{fd, POLLIN, 0};
    (void)::poll(&p, 1, 1);
    const std::int64_t now = crease::rt::now_ns();
    const double t = static_cast<double>(now - t0) * 1e-9;
    if (seconds > 0 && t >= seconds) break;
    const bool want_silent = silent_after >= 0 && t >= silent_after && t < silent_after + silent_for;
    if (want_silent != silent) {
      silent = want_silent;
      set_silent(silent);
    }
    step(now);
  }
  return 0;
}

// A simulated CAN device (hand or arm) on its mock bus node.
int serve_can_device(const Args& a, const MockCanBus& bus, sim::CanopenDevice& dev) {
  return serve(a, bus.fd(), [&](std::int64_t t) { dev.step(t); }, [&](bool s) { dev.set_silent(s); });
}

MockCanBusConfig bus_config(const Args& a, std::uint32_t node) {
  if (!a.has("bus")) throw std::invalid_argument("option --bus is required");
  return {a.str("bus"), node, static_cast<std::uint32_t>(a.num("bitrate", 1'000'000)),
          static_cast<std::uint32_t>(a.num("data-bitrate", 5'000'000)), a.str("group")};
}

// "127.0.0.1:PORT" or "localhost:PORT" (the bridge serves the loopback interface only).
std::uint16_t listen_port(const std::string& v) {
  const std::size_t colon = v.rfind(':');
  const std::string host = colon == std::string::npos ? "" : v.substr(0, colon);
  const std::string port = colon == std::string::npos ? v : v.substr(colon + 1);
  if (host != "127.0.0.1" && host != "localhost") {
    throw std::invalid_argument("option --listen: '" + v + "' must be 127.0.0.1:PORT (the bridge serves loopback only)");
  }
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (port.empty() || *end != '\0' || p < 0 || p > 65535) {
    throw std::invalid_argument("option --listen: '" + port + "' is not a port (0..65535)");
  }
  return static_cast<std::uint16_t>(p);
}

std::uint8_t node_of(const Args& a) {
  const double n = a.num("node", -1);
  if (n < 1 || n > 126) throw std::invalid_argument("option --node must be 1..126");
  return static_cast<std::uint8_t>(n);
}

int run(const Args& a) {
  struct sigaction sa{};
  sa.sa_handler = on_signal;
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
  if (a.has("fifo")) {
    sched_param sp{};
    sp.sched_priority = static_cast<int>(a.num("fifo", 0));
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0) std::fprintf(stderr, "crease-simdevice: SCHED_FIFO not permitted, running SCHED_OTHER\n");
  }
  if (a.mode == "broker") {
    if (!a.has("bus")) throw std::invalid_argument("option --bus is required");
    MockCanBrokerConfig cfg{a.str("bus"), static_cast<std::uint32_t>(a.num("bitrate", 1'000'000)),
                            static_cast<std::uint32_t>(a.num("data-bitrate", 5'000'000)), a.has("pace"),
                            a.str("group")};
    CanFaultConfig f;
    f.seed = static_cast<std::uint64_t>(a.num("seed", 1));
    f.drop = a.num("drop", 0);
    f.corrupt = a.num("corrupt", 0);
    f.duplicate = a.num("duplicate", 0);
    f.reorder = a.num("reorder", 0);
    f.delay = a.num("delay", 0);
    f.delay_ns = static_cast<std::int64_t>(a.num("delay-ms", 2) * 1e6);
    f.error_frame = a.num("error-frames", 0);
    MockCanBroker broker(cfg);
    broker.set_faults(f);
    std::printf("broker: %s\n", cfg.name.c_str());
    std::fflush(stdout);
    const std::int64_t t0 = crease::rt::now_ns();
    const double seconds = a.num("seconds", 0);
    while (!g_stop && (seconds <= 0 || static_cast<double>(crease::rt::now_ns() - t0) * 1e-9 < seconds)) ::usleep(10'000);
    return 0;
  }
  if (a.mode == "hand") {
    const std::uint8_t node = node_of(a);
    MockCanBus bus(bus_config(a, node));
    sim::SimHandConfig cfg;
    cfg.node = node;
    cfg.pressure_sensors = a.has("pressure");
    sim::SimHand hand(bus, cfg);
    return serve_can_device(a, bus, hand);
  }
  if (a.mode == "arm") {
    const std::uint8_t node = node_of(a);
    MockCanBus bus(bus_config(a, node));
    sim::SimArmConfig cfg;
    cfg.node = node;
    sim::SimArm arm(bus, cfg);
    return serve_can_device(a, bus, arm);
  }
  if (a.mode == "tactile") {
    PtyPair pty;
    sim::SimTactile dev(pty.master_fd());
    for (int f = 0; f < 5; ++f) dev.set_contact_force(f, static_cast<float>(a.num("force", 1.0)));
    std::printf("pty: %s\n", pty.slave_path().c_str());
    std::fflush(stdout);
    return serve(a, pty.master_fd(), [&](std::int64_t t) { dev.step(t); }, [&](bool s) { dev.set_silent(s); });
  }
  if (a.mode == "record") {
    if (!a.has("out")) throw std::invalid_argument("option --out is required");
    MockCanBus bus(bus_config(a, static_cast<std::uint32_t>(a.num("node", 127))));
    RecordingCanBus rec(bus, "can0");
    CandumpWriter log(a.str("out"));
    std::size_t lines = 0;
    RxFrame rx;
    const int rc = serve(
        a, bus.fd(),
        [&](std::int64_t) {
          while (rec.try_receive(rx) != RecvResult::empty) {
          }
          if (const std::size_t n = rec.drain_to(log); n > 0) {
            lines += n;
            log.flush();  // the log is readable while it grows (tail -f, tests)
          }
        },
        [](bool) {});
    while (rec.try_receive(rx) != RecvResult::empty) {  // what arrived before the stop
    }
    lines += rec.drain_to(log);
    log.flush();
    std::fprintf(stderr, "crease-simdevice: recorded %zu frames (%llu dropped)\n", lines,
                 static_cast<unsigned long long>(rec.dropped()));
    return rc;
  }
  if (a.mode == "replay") {
    if (!a.has("in")) throw std::invalid_argument("option --in is required");
    MockCanBus bus(bus_config(a, static_cast<std::uint32_t>(a.num("node", 126))));
    CandumpReader log(a.str("in"));
    const std::size_t n = replay_candump(log, bus, a.num("speed", 1.0));
    std::fprintf(stderr, "crease-simdevice: replayed %zu frames\n", n);
    return 0;
  }
  if (a.mode == "socketcand") {
    const std::uint16_t port = listen_port(a.str("listen", "127.0.0.1:29536"));
    MockCanBus bus(bus_config(a, static_cast<std::uint32_t>(a.num("node", 125))));
    SocketcandBridge bridge(bus, port, a.str("interface", "can0"));
    std::printf("socketcand: 127.0.0.1:%u\n", static_cast<unsigned>(bridge.port()));
    std::fflush(stdout);
    const std::int64_t t0 = crease::rt::now_ns();
    const double seconds = a.num("seconds", 0);
    while (!g_stop && (seconds <= 0 || static_cast<double>(crease::rt::now_ns() - t0) * 1e-9 < seconds)) ::usleep(10'000);
    const SocketcandBridgeStats st = bridge.stats();
    std::fprintf(stderr, "crease-simdevice: socketcand: %llu frames to clients, %llu from clients\n",
                 static_cast<unsigned long long>(st.to_clients), static_cast<unsigned long long>(st.from_clients));
    return 0;
  }
  throw std::invalid_argument("unknown mode '" + a.mode + "' (broker, hand, arm, tactile, record, replay, socketcand)");
}
}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "crease-simdevice: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crease-simdevice: %s\n", e.what());
    return 1;
  }
}
