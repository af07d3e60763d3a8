// A rig of four simulated devices (two hands, two arms) as crease-simdevice processes, each
// on its own mocked CAN FD bus whose broker runs in the test process (so faults can be
// injected), and the four host links driven by a 1 kHz loop in the test thread.
#pragma once

#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <memory>
#include <string>
#include <vector>

#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/host/arm_host.h"
#include "drivers/host/hand_host.h"

extern char** environ;

namespace crease::drivers::testing {

inline pid_t spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  if (posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
  return pid;
}

struct Rig {
  static constexpr int kDevices = 4;
  std::string tag = std::to_string(::getpid());
  std::vector<std::unique_ptr<MockCanBroker>> brokers;
  std::vector<std::unique_ptr<MockCanBus>> buses;
  std::vector<pid_t> children;
  std::unique_ptr<HandHost> hands[2];
  std::unique_ptr<ArmHost> arms[2];

  std::string bus_name(int i) const { return "hil-" + tag + "-" + std::to_string(i); }

  bool fifo = false;  // the loop, the brokers and the devices run under SCHED_FIFO

  Rig() {
    // Devices are firmware with deadlines: where permitted, the test loop (and the broker
    // threads it creates, which inherit it) and the device processes run under SCHED_FIFO so
    // compiler load on a shared machine does not starve them. Otherwise tolerances widen.
    sched_param sp{};
    sp.sched_priority = 80;
    fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
    const std::string exe = std::string(CREASE_BIN_DIR) + "/crease-simdevice";
    const std::vector<std::string> rt = fifo ? std::vector<std::string>{"--fifo", "70"} : std::vector<std::string>{};
    auto with_rt = [&](std::vector<std::string> v) {
      v.insert(v.end(), rt.begin(), rt.end());
      return v;
    };
    for (int i = 0; i < kDevices; ++i) {
      brokers.push_back(std::make_unique<MockCanBroker>(MockCanBrokerConfig{bus_name(i), 1'000'000, 5'000'000, false}));
      buses.push_back(std::make_unique<MockCanBus>(MockCanBusConfig{bus_name(i), 100, 1'000'000, 5'000'000}));
    }
    children.push_back(spawn(with_rt({exe, "hand", "--bus", bus_name(0), "--node", "1"})));
    children.push_back(spawn(with_rt({exe, "hand", "--bus", bus_name(1), "--node", "2", "--pressure"})));
    children.push_back(spawn(with_rt({exe, "arm", "--bus", bus_name(2), "--node", "10"})));
    children.push_back(spawn(with_rt({exe, "arm", "--bus", bus_name(3), "--node", "11"})));
    hands[0] = std::make_unique<HandHost>(*buses[0], HandHostConfig{.node = 1});
    hands[1] = std::make_unique<HandHost>(*buses[1], HandHostConfig{.node = 2, .pressure_sensors = true});
    arms[0] = std::make_unique<ArmHost>(*buses[2], ArmHostConfig{.node = 10});
    arms[1] = std::make_unique<ArmHost>(*buses[3], ArmHostConfig{.node = 11});
  }

  bool all_spawned() const {
    for (pid_t p : children)
      if (p <= 0) return false;
    return true;
  }
  bool all_connected() const {
    for (const auto& b : brokers)
      if (b->connected_nodes() < 2) return false;
    return true;
  }

  ~Rig() {
    sched_param sp{};
    (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &sp);
    for (pid_t p : children)
      if (p > 0) ::kill(p, SIGTERM);
    for (pid_t p : children)
      if (p > 0) ::waitpid(p, nullptr, 0);
  }
};

}  // namespace crease::drivers::testing
