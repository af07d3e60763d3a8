// hand_driver x2 and arm_driver x2 as plugins in a PluginHost 1 kHz loop, the four simulated
// devices as crease-simdevice processes on their mocked buses (brokers in this process).
#include <doctest/doctest.h>

#include <chrono>
#include <thread>

#include "core/plugin_host.h"
#include "core/port_types/arm.h"
#include "core/port_types/hand.h"
#include "hil_rig.h"
#include "rt/alloc_guard.h"

using namespace crease;
using crease::drivers::testing::Rig;

namespace {
// Each instance's ports get its name as prefix (hand_r.hand_state, hand_r.hand_command, ...).
InstanceSpec spec(const std::string& name, const std::string& lib, int order, const std::string& yaml) {
  InstanceSpec s;
  const std::string kind = lib == "hand_driver" ? "hand" : "arm";
  s.ports = {{kind + "_state", name + "." + kind + "_state"}, {kind + "_command", name + "." + kind + "_command"}};
  s.name = name;
  s.library = lib;
  s.loop = "control";
  s.order = order;
  s.params = Params(YAML::Load(yaml), "test.yaml", name + ".params");
  return s;
}
template <class T>
T read_port(PluginHost& host, const std::string& port) {
  T v{};
  const auto* ch = host.ports().find_latest(port);
  REQUIRE_MESSAGE(ch != nullptr, port);
  ch->read(&v, 0);
  return v;
}
}  // namespace

TEST_CASE("four driver plugins in the control loop against four device processes, 5 s") {
  Rig rig;  // its own host links stay idle: the plugins join each bus as node 101
  REQUIRE(rig.all_spawned());
  for (int i = 0; i < 500 && !rig.all_connected(); ++i) ::usleep(2000);
  REQUIRE(rig.all_connected());
  for (auto& h : rig.hands) h.reset();  // the rig's own host links and their idle nodes leave
  for (auto& a : rig.arms) a.reset();
  rig.buses.clear();
  PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"control", 1000.0, rig.fifo ? 80 : 0, -1});
  host.add_instance(spec("hand_r", "hand_driver", 1, "{bus: " + rig.bus_name(0) + ", node: 1, host_node: 101}"));
  host.add_instance(spec("hand_l", "hand_driver", 2,
                         "{bus: " + rig.bus_name(1) + ", node: 2, host_node: 101, pressure_sensors: true}"));
  host.add_instance(spec("arm_r", "arm_driver", 3, "{bus: " + rig.bus_name(2) + ", node: 10, host_node: 101}"));
  host.add_instance(spec("arm_l", "arm_driver", 4, "{bus: " + rig.bus_name(3) + ", node: 11, host_node: 101}"));
  host.start();
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const auto allocs = rt::rt_allocation_count();
  HandState h0 = read_port<HandState>(host, "hand_r.hand_state");
  ArmState a0 = read_port<ArmState>(host, "arm_r.arm_state");
  // Sampled every 10 ms for 4 s: a single reading is a snapshot of the machine's load (two
  // late answers make a link `fault` and the driver quick-stops the drive for a few cycles).
  int samples = 0, enabled_r = 0, enabled_l = 0, fault_h = 0, fault_a = 0;
  for (; samples < 400; ++samples) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const ArmState ar = read_port<ArmState>(host, "arm_r.arm_state");
    const ArmState alv = read_port<ArmState>(host, "arm_l.arm_state");
    const HandState hr = read_port<HandState>(host, "hand_r.hand_state");
    enabled_r += ar.drive_state == 4 ? 1 : 0;  // operation enabled
    enabled_l += alv.drive_state == 4 ? 1 : 0;
    fault_h += hr.health == DeviceHealth::fault ? 1 : 0;
    fault_a += ar.health == DeviceHealth::fault ? 1 : 0;
  }
  CHECK(rt::rt_allocation_count() == allocs);  // steady state: no allocation on the loop thread
  const HandState h1 = read_port<HandState>(host, "hand_r.hand_state");
  const HandState hl = read_port<HandState>(host, "hand_l.hand_state");
  const ArmState a1 = read_port<ArmState>(host, "arm_r.arm_state");
  const ArmState al = read_port<ArmState>(host, "arm_l.arm_state");
  for (const auto& i : host.instances()) {  // what the firewall made of each, should a check below fail
    MESSAGE(i.name << ": " << std::string(to_string(i.state)) << ", last fault " << std::string(to_string(i.last_fault))
                   << ", device faults " << i.stats->device_faults.load() << ", over budget " << i.stats->over_budget.load());
  }
  host.stop();
  const auto sent_h = h1.commands_sent - h0.commands_sent;
  const auto sent_a = a1.commands_sent - a0.commands_sent;
  MESSAGE("hand_r sent " << sent_h << " failed " << h1.commands_failed - h0.commands_failed << "; arm_r sent " << sent_a
                         << " failed " << a1.commands_failed - a0.commands_failed);
  CHECK(sent_h > 2000);  // the loop ran (4000 cycles at 1 kHz; skipped periods are not replayed)
  CHECK(sent_a > 2000);
  // Late round trips (commands_failed) are a figure of the machine's load (crease-bench bus
  // prints their share), not compared here. What a broken link cannot do: the device applies
  // the commands, late or not: the seq its statuses echo advances with the seqs sent.
  const auto applied_h = static_cast<std::uint16_t>(h1.acked_seq - h0.acked_seq);
  const auto applied_a = static_cast<std::uint16_t>(a1.acked_seq - a0.acked_seq);
  MESSAGE("seqs applied: hand_r " << applied_h << ", arm_r " << applied_a);
  CHECK(applied_h * 2 > sent_h);  // ~4000 sent: only a device 2 s behind fails this
  CHECK(applied_a * 2 > sent_a);
  CHECK(hl.acked_seq != 0);  // the left devices applied commands too
  CHECK(al.acked_seq != 0);
  MESSAGE("of " << samples << " samples: arm_r enabled " << enabled_r << ", arm_l enabled "
                << enabled_l << ", hand_r fault " << fault_h << ", arm_r fault " << fault_a);
  CHECK(enabled_r * 2 > samples);  // the drivers enabled the drives, and keep them enabled
  CHECK(enabled_l * 2 > samples);
  CHECK(fault_h * 2 < samples);
  CHECK(fault_a * 2 < samples);
}
