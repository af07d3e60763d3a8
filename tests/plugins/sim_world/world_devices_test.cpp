// The world felt through the real drivers (label hil): hand_driver x2 and arm_driver x2 in a
// 1 kHz control loop, over the mocked CAN FD buses and the right hand's serial tactile link,
// against the sim_world plugin in a 1 kHz loop of its own half a period behind, whose devices
// step in lockstep with the world (plugins/sim_world/world_devices.h, world_tactile.h). The
// test writes arm_command and hand_command as a controller would. An arm commanded through
// arm_command moves the world's fingertip; an index driven down onto the sheet deviates from
// its target, hand_state reports the world's joint angles, and the fingertip's force reaches
// the right hand's taxel matrix (tactile) and the left hand's PST sensors (hand_state
// pressure_kpa) as their calibration says (config/robot/crease_robot.yaml); commanded disabled,
// the hand goes limp in the world and presses nothing. Failing variant: the world's contacts
// switched off: no joint deviates, no sensor reads a force.
// Waits are on conditions (a loaded machine is slow, never wrong); no timing is asserted.
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <string>
#include <thread>

#include "core/plugin_host.h"
#include "core/port_types/arm.h"
#include "core/port_types/hand.h"
#include "core/port_types/tactile.h"
#include "core/port_types/world_state.h"
#include "rt/clock.h"
#include "scene.h"

using namespace scene;

namespace {

template <class P>
bool eventually(P pred, int seconds = 20) {
  for (int i = 0; i < seconds * 1000 && !pred(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return pred();
}

std::string degrees(const double* q, int n) {
  std::string s = "[";
  for (int i = 0; i < n; ++i) s += (i ? ", " : "") + std::to_string(q[i] * 180.0 / std::numbers::pi);
  return s + "]";
}

InstanceSpec spec(const std::string& name, const std::string& lib, const std::string& loop, int order,
                  const std::string& yaml, std::map<std::string, std::string> ports = {}) {
  InstanceSpec s;
  s.name = name;
  s.library = lib;
  s.loop = loop;
  s.order = order;
  s.params = Params(YAML::Load(yaml), "test.yaml", name + ".params");
  s.ports = std::move(ports);
  return s;
}

// SIDE's index pad over the sheet at (x, y) and height z (mm), palm forward and down by 30 deg,
// the other fingers bent back (the press scene of sim_world_press_test.cpp).
struct Poses {
  Poses(robot::Side s, double x_, double y_) : side(s), ik(robot_model(), s), x(x_), y(y_) {}
  robot::Side side;
  ArmIk ik;
  double x, y;
  HandQ hand = index_out();
  ArmQ at(double z, const ArmQ& guess) { return ik.solve("ffpad", {x, y, z}, palm_forward_down(side, deg(30)), hand, guess); }
};

// The world, both hands' and both arms' drivers, and the test as the commands' writer for SIDE
// ("r" or "l"). The other side is parked (sim_world's default pose) and held by its drivers.
struct Robot {
  Robot(bool contacts, const char* side, const ArmQ& start, const HandQ& hand) : host({CREASE_PLUGIN_DIR}), s(side) {
    const std::string prefix = "crease-t-wd-" + std::to_string(::getpid()) + (contacts ? "-on" : "-off");
    // Where permitted the loops run under SCHED_FIFO as in config/sim.yaml, and so does the
    // brokers' thread (it inherits this thread's policy when the world creates the first
    // broker): a compiler-loaded machine must not starve the drivers for the devices' 20 ms
    // watchdog (a hand that times out goes limp and lets go of the sheet).
    sched_param sp{};
    sp.sched_priority = 60;
    const bool fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
    host.add_loop({"control", 1000.0, fifo ? 80 : 0, -1});
    host.add_loop({"world", 1000.0, fifo ? 70 : 0, -1, 500'000});  // half a period behind the drivers
    InstanceSpec world = spec("world", "sim_world", "world", 0,
                              "{robot: " CREASE_SOURCE_DIR "/config/robot/crease_robot.yaml, bus_prefix: " + prefix +
                                  ", randomise: false, initial_stiffness_nm_per_rad: 2, hand_contacts: " +
                                  (contacts ? "true" : "false") + ", arm_" + s + "_deg: " + degrees(start.data(), 7) +
                                  ", hand_" + s + "_deg: " + degrees(hand.data(), 20) + "}");
    world.budget_ns = 0;  // as config/sim.yaml: a late world step delays its devices with it, it is no fault
    host.add_instance(world);
    // timeout_cycles wide: a late wake-up of a loaded machine must not put a link in its safe state.
    const std::string common = "{bus_prefix: " + prefix + ", timeout_cycles: 100, ";
    host.add_instance(spec("hand_r", "hand_driver", "control", 1, common + "bus: hand_r, node: 1, tactile_device: tactile_r}",
                           {{"hand_state", "hand_r.state"}, {"hand_command", "hand_r.command"}, {"tactile", "hand_r.tactile"}}));
    host.add_instance(spec("hand_l", "hand_driver", "control", 2, common + "bus: hand_l, node: 2, pressure_sensors: true}",
                           {{"hand_state", "hand_l.state"}, {"hand_command", "hand_l.command"}}));
    host.add_instance(spec("arm_r", "arm_driver", "control", 3, common + "bus: arm_r, node: 10}",
                           {{"arm_state", "arm_r.state"}, {"arm_command", "arm_r.command"}}));
    host.add_instance(spec("arm_l", "arm_driver", "control", 4, common + "bus: arm_l, node: 11}",
                           {{"arm_state", "arm_l.state"}, {"arm_command", "arm_l.command"}}));
    hand_cmd = host.ports().bind_latest_writer("hand_" + s + ".command", port_type_of<HandCommand>(), "test");
    arm_cmd = host.ports().bind_latest_writer("arm_" + s + ".command", port_type_of<ArmCommand>(), "test");
    host.start();
    sp.sched_priority = 0;
    if (fifo) (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &sp);
  }
  ~Robot() { host.stop(); }
  template <class T>
  T read(const std::string& port) {
    T v{};
    const auto* ch = host.ports().find_latest(port);
    REQUIRE_MESSAGE(ch != nullptr, port);
    ch->read(&v, 0);
    return v;
  }
  HandState hand_state() { return read<HandState>("hand_" + s + ".state"); }
  ArmState arm_state() { return read<ArmState>("arm_" + s + ".state"); }
  void command_hand(const HandQ& q, double stiffness) {
    HandCommand c;
    for (int j = 0; j < HandCommand::kJoints; ++j) {
      c.target_rad[j] = static_cast<float>(q[j]);
      c.stiffness_nm_per_rad[j] = static_cast<float>(stiffness);
    }
    c.enable = 1;
    c.timestamp_ns = rt::now_ns();
    hand_cmd->write(&c, c.timestamp_ns);
  }
  void command_arm(const ArmQ& q) {
    ArmCommand c;
    for (int j = 0; j < ArmCommand::kJoints; ++j) c.position_rad[j] = static_cast<float>(q[j]);
    c.timestamp_ns = rt::now_ns();
    arm_cmd->write(&c, c.timestamp_ns);
  }
  // The arm's drive has reached q (as arm_state reports it) and the world has stepped 300 more
  // steps (0.3 s of world time) since: the hand has settled.
  bool reach(const ArmQ& q) {
    const bool reached = eventually([&] {
      const ArmState a = arm_state();
      double worst = 0;
      for (int j = 0; j < 7; ++j) worst = std::max(worst, std::fabs(a.position_rad[j] - q[j]));
      return worst < 1e-4;
    });
    const std::uint64_t step = read<WorldState>("world_state").step;
    return reached && eventually([&] { return read<WorldState>("world_state").step > step + 300; });
  }
  PluginHost host;
  std::string s;
  rt::LatestChannel* hand_cmd = nullptr;
  rt::LatestChannel* arm_cmd = nullptr;
};

struct Pressed {
  double lift_dz_mm = 0, lift_dxy_mm = 0;  // the fingertip's motion when the arm lifted it 20 mm
  double ffj3_dev_rad = 0, wrj1_dev_rad = 0;  // hand_state's angle - the commanded target
  double worst_vs_world_rad = 0;  // hand_state against world_state's joint angles
  double force_n = 0, tip_z_mm = 0;  // the world's: the index's normal force, its pad's height
  // Right hand: the index's taxel matrix as a force (sum x taxel_area_mm2), the worst taxel of
  // the other four fingertips (kPa). Left hand: the index's PST sensor (kPa), the others' worst.
  double taxel_force_n = -1, other_taxels_kpa = -1, pst_kpa = -1, other_pst_kpa = -1;
  DeviceHealth hand_health = DeviceHealth::fault, arm_health = DeviceHealth::fault, tactile_health = DeviceHealth::fault;
  double limp_force_n = -1;  // the index's force once the hand is commanded disabled (limp)
};

// From the pad 20 mm over the sheet: up to 40 mm (the arm moves the fingertip), then down to
// 6 mm below the table's top (the index presses onto the sheet on the table).
Pressed run(bool contacts, robot::Side side) {
  const bool right = side == robot::Side::right;
  Poses poses(side, right ? 0.0 : -20.0, right ? 0.0 : 40.0);
  const ArmQ q20 = poses.at(20, arm_guess()), q40 = poses.at(40, q20), qdown = poses.at(-6, q20);
  Robot robot(contacts, right ? "r" : "l", q20, poses.hand);
  const int me = static_cast<int>(side);
  REQUIRE(eventually([&] { return robot.arm_state().health == DeviceHealth::ok && robot.hand_state().health == DeviceHealth::ok; }));
  robot.command_hand(poses.hand, 2.0);
  robot.command_arm(q20);
  REQUIRE(eventually([&] { return robot.arm_state().drive_state == 4; }));  // operation enabled
  REQUIRE(robot.reach(q20));
  Pressed out;
  const WorldState w20 = robot.read<WorldState>("world_state");
  robot.command_arm(q40);
  REQUIRE(robot.reach(q40));
  const WorldState w40 = robot.read<WorldState>("world_state");
  const WorldFingertip &a = w20.hand[me].tip[0], &b = w40.hand[me].tip[0];
  out.lift_dz_mm = b.position_mm[2] - a.position_mm[2];
  out.lift_dxy_mm = std::hypot(b.position_mm[0] - a.position_mm[0], b.position_mm[1] - a.position_mm[1]);

  robot.command_arm(qdown);
  REQUIRE(robot.reach(qdown));
  // Read the hand's state between two world states 30 ms apart that agree (the press has
  // settled: the index's force steady, the reported angles the world's).
  HandState h{};
  WorldState w{};
  double angle_gap = 0, force_change = 0;
  std::uint64_t steps = 0;
  const bool settled = eventually([&] {
    const WorldState w1 = robot.read<WorldState>("world_state");
    if (!eventually([&] { return robot.read<WorldState>("world_state").step > w1.step + 30; })) return false;
    h = robot.hand_state();
    w = robot.read<WorldState>("world_state");
    angle_gap = 0;
    for (int j = 0; j < 20; ++j) angle_gap = std::max(angle_gap, double(std::fabs(h.position_rad[j] - w.hand[me].joint_rad[j])));
    force_change = std::fabs(w.hand[me].tip[0].normal_force_n - w1.hand[me].tip[0].normal_force_n);
    steps = w.step - w1.step;
    return force_change < 0.002 && angle_gap < 1e-4;
  });
  INFO("last try: " << steps << " steps, force change " << force_change << " N, hand_state vs the world " << angle_gap << " rad");
  REQUIRE(settled);
  out.ffj3_dev_rad = h.position_rad[FFJ3] - poses.hand[FFJ3];
  out.wrj1_dev_rad = h.position_rad[WRJ1] - poses.hand[WRJ1];
  for (int j = 0; j < 20; ++j)
    out.worst_vs_world_rad = std::max(out.worst_vs_world_rad, double(std::fabs(h.position_rad[j] - w.hand[me].joint_rad[j])));
  out.force_n = w.hand[me].tip[0].normal_force_n;
  out.tip_z_mm = w.hand[me].tip[0].position_mm[2];
  out.hand_health = h.health;
  out.arm_health = robot.arm_state().health;
  const robot::SideParams& sp = robot_model().params().side(side);
  if (right) {
    REQUIRE(eventually([&] { return robot.read<Tactile>("hand_r.tactile").health == DeviceHealth::ok; }));
    const Tactile t = robot.read<Tactile>("hand_r.tactile");
    out.tactile_health = t.health;
    double sum = 0;
    out.other_taxels_kpa = 0;
    for (int k = 0; k < Tactile::kTaxels; ++k) {
      sum += t.pressure_kpa[0][k];
      for (int f = 1; f < Tactile::kFingertips; ++f) out.other_taxels_kpa = std::max(out.other_taxels_kpa, double(t.pressure_kpa[f][k]));
    }
    out.taxel_force_n = sum * sp.tactile.taxel.taxel_area_mm2 / 1000.0;
  } else {
    REQUIRE(eventually([&] { return (robot.hand_state().pressure_valid & 0x1F) == 0x1F; }));
    out.pst_kpa = h.pressure_kpa[0];
    out.other_pst_kpa = 0;
    for (int f = 1; f < 5; ++f) out.other_pst_kpa = std::max(out.other_pst_kpa, double(std::fabs(h.pressure_kpa[f])));
  }
  const std::string tag = std::string(right ? "right" : "left") + (contacts ? ", contacts on" : ", contacts off");
  MESSAGE(tag << ": lift "
          << out.lift_dz_mm << " mm up, " << out.lift_dxy_mm << " mm aside; pressed: FFJ3 " << out.ffj3_dev_rad
          << " rad, WRJ1 " << out.wrj1_dev_rad << " rad off target, index force " << out.force_n << " N, pad at z "
          << out.tip_z_mm << " mm; hand_state vs the world " << out.worst_vs_world_rad << " rad; taxels "
          << out.taxel_force_n << " N (others' worst " << out.other_taxels_kpa << " kPa); PST " << out.pst_kpa
          << " kPa (others' worst " << out.other_pst_kpa << "); hand commands sent " << h.commands_sent
          << ", not acknowledged within 2 cycles " << h.commands_failed);
  // Disabled, the hand goes limp (zero stiffness where it is): nothing presses the sheet.
  HandCommand off;
  off.timestamp_ns = rt::now_ns();
  robot.hand_cmd->write(&off, off.timestamp_ns);
  REQUIRE(eventually([&] { return robot.hand_state().safe_state == 1; }));
  const std::uint64_t step = robot.read<WorldState>("world_state").step;
  REQUIRE(eventually([&] { return robot.read<WorldState>("world_state").step > step + 300; }));
  out.limp_force_n = robot.read<WorldState>("world_state").hand[me].tip[0].normal_force_n;
  MESSAGE(tag << ": limp, the index presses " << out.limp_force_n << " N");
  return out;
}

}  // namespace

TEST_CASE("the drivers against the world: the arm moves the fingertip, the pressed right index deviates, its taxels read the force") {
  const Pressed on = run(true, robot::Side::right);
  CHECK(on.lift_dz_mm == doctest::Approx(20.0).epsilon(0.01));
  CHECK(on.lift_dxy_mm < 0.2);
  CHECK(on.force_n > 0.1);
  CHECK(std::fabs(on.ffj3_dev_rad) > 0.005);  // the sheet on the table pushes the index back
  CHECK(std::fabs(on.wrj1_dev_rad) > 0.005);
  CHECK(on.tip_z_mm > 0.0);                   // held on the sheet, not driven into the table
  CHECK(on.worst_vs_world_rad < 1e-4);        // what the driver reads is the world's angle
  // The taxel matrix, calibrated (taxel_area_mm2), reads the world's force within its
  // sensitivity: the taxels under the threshold (8 kPa) are lost, the noise (1 kPa) remains.
  CHECK(on.taxel_force_n == doctest::Approx(on.force_n).epsilon(0.3));
  CHECK(on.other_taxels_kpa == 0.0);          // the other fingertips touch nothing
  CHECK(on.hand_health != DeviceHealth::fault);
  CHECK(on.arm_health != DeviceHealth::fault);
  CHECK(on.tactile_health == DeviceHealth::ok);
  CHECK(on.limp_force_n < 0.01);  // limp: the press (0.69 N while enabled) is gone

  // Failing variant: without the world's contacts the finger meets nothing and keeps its target.
  const Pressed off = run(false, robot::Side::right);
  CHECK(off.lift_dz_mm == doctest::Approx(20.0).epsilon(0.01));
  CHECK(off.force_n == 0.0);
  CHECK(std::fabs(off.ffj3_dev_rad) < 1e-4);
  CHECK(std::fabs(off.wrj1_dev_rad) < 1e-4);
  CHECK(off.tip_z_mm < -5.0);  // through the sheet and the table top
  CHECK(off.taxel_force_n == 0.0);
}

TEST_CASE("the drivers against the world: the pressed left index deviates, its PST sensor reads the force") {
  const double kpa_per_n = robot_model().params().side(robot::Side::left).tactile.pst.kpa_per_n;
  const Pressed on = run(true, robot::Side::left);
  CHECK(on.lift_dz_mm == doctest::Approx(20.0).epsilon(0.01));
  CHECK(on.force_n > 0.1);
  CHECK(std::fabs(on.ffj3_dev_rad) > 0.005);
  CHECK(on.worst_vs_world_rad < 1e-4);
  // kpa_per_n x the force, less what the high-pass (30 s) took in the press's first second.
  CHECK(on.pst_kpa == doctest::Approx(kpa_per_n * on.force_n).epsilon(0.05));
  CHECK(on.other_pst_kpa < 0.1);  // the noise floor (0.01 kPa) of fingertips touching nothing

  const Pressed off = run(false, robot::Side::left);
  CHECK(off.force_n == 0.0);
  CHECK(std::fabs(off.ffj3_dev_rad) < 1e-4);
  CHECK(off.pst_kpa < 0.1);
}
