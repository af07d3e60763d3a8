// Test support: one hand's control chain (contact_controller -> force_controller ->
// hand_command, the real plugins in a PluginHost's control loop) closed around the simulated
// world (plugins/sim_world), stepped here at 1 ms, one control cycle per world step, with no
// thread and no clock (deterministic).
//
// Every cycle: the world's state after the last step becomes the drivers' ports (HandState:
// the joint angles quantised to the wire's 1e-4 rad; the left hand's PST pressures and the
// right hand's taxel matrices at 250 Hz through tactile_model.h); the loop runs one cycle; the
// newest hand_command goes to World::command_hand_rt; the arm follows a precomputed joint path
// (IK solved at set-up, not in the loop) standing in for arm_motion: it advances along the path
// at a set speed and, told to stop on contact, decelerates from the cycle contact_state reports
// one; then the world steps. Faults are injected by editing or withholding the ports' values.
// Scores come from the world's truth (World::state()), never from the controllers' beliefs.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "core/plugin_host.h"
#include "core/port_types/contact.h"
#include "core/port_types/hand.h"
#include "core/port_types/hand_control.h"
#include "core/port_types/hand_goal.h"
#include "core/port_types/tactile.h"
#include "plugins/sim_world/scene.h"
#include "plugins/sim_world/world_config.h"
#include "plugins/sim_world/tactile_model.h"
#include "rt/alloc_guard.h"
#include "rt/latest.h"

namespace hand_world {

using namespace scene;

// A joint path for the arm: IK solutions every step_mm along a polyline of the tool's points.
struct ArmPath {
  std::vector<ArmQ> q;
  std::vector<Vec3> p;  // the tool's commanded point at each sample
  double step_mm = 0.25;
  [[nodiscard]] double length_mm() const { return step_mm * static_cast<double>(q.size() - 1); }
  [[nodiscard]] ArmQ at(double s_mm) const {
    const double x = std::clamp(s_mm / step_mm, 0.0, static_cast<double>(q.size() - 1));
    const auto i = std::min(static_cast<std::size_t>(x), q.size() - 2);
    const double t = x - static_cast<double>(i);
    ArmQ out{};
    for (int j = 0; j < robot::kArmJoints; ++j) out[j] = (1 - t) * q[i][j] + t * q[i + 1][j];
    return out;
  }
  [[nodiscard]] Vec3 point(double s_mm) const {
    const double x = std::clamp(s_mm / step_mm, 0.0, static_cast<double>(p.size() - 1));
    const auto i = std::min(static_cast<std::size_t>(x), p.size() - 2);
    const double t = x - static_cast<double>(i);
    return p[i] + t * (p[i + 1] - p[i]);
  }
};

struct Options {
  robot::Side side = robot::Side::left;
  WorldParams world = nominal();
  double stiffness = 3.0;  // N m/rad: the hand's joints (world's initial and the controller's default)
  Vec3 start{-20, 40, 6};  // the index pad's first point (mm, world)
  std::string contact_params;  // YAML flow-map entries added to the side's defaults ("k: v, ...")
  std::string force_params;
  bool with_contact = true;
  bool with_force = true;
  std::uint64_t sensor_seed = 1;
  double joint_noise_rad = 0.0;  // Gaussian noise on the measured joints (the world's are exact)
};

class HandWorld {
 public:
  explicit HandWorld(Options o)
      : o_(std::move(o)), me_(static_cast<int>(o_.side)), ik_(robot_model(), o_.side),
        pst_(robot_model().params().side(robot::Side::left).tactile, o_.sensor_seed),
        taxels_(robot_model().params().side(robot::Side::right).tactile, o_.sensor_seed + 17),
        noise_(robot_model().params().side(robot::Side::left).tactile, o_.sensor_seed + 31),
        host_({CREASE_PLUGIN_DIR}) {
    hand_q_ = index_out();
    palm_ = palm_forward_down(o_.side, deg(30));
    q_ = ik_.solve("ffpad", o_.start, palm_, hand_q_, arm_guess());
    // The other arm parked as creased parks it (sim_world's default: its pad 300 mm over the
    // table beside the sheet).
    for (int j = 0; j < robot::kArmJoints; ++j) q_other_[j] = world::kParkedArmDeg[1 - me_][j] * std::numbers::pi / 180.0;
    WorldParams& p = o_.world;
    p.initial_stiffness_nm_per_rad = o_.stiffness;
    p.initial_arm_rad[me_] = q_;
    p.initial_arm_rad[1 - me_] = q_other_;
    p.initial_hand_rad[me_] = hand_q_;
    world_ = std::make_unique<World>(robot_model(), p);
    stiffness_.fill(o_.stiffness);
    target_ = hand_q_;

    loop_ = &host_.add_loop({"control", 1000.0, 0, -1});
    auto& ports = host_.ports();
    hand_w_ = ports.bind_latest_writer("hand_state", crease::port_type_of<crease::HandState>(), "test");
    if (right()) tactile_w_ = ports.bind_latest_writer("tactile", crease::port_type_of<crease::Tactile>(), "test");
    goal_w_ = ports.bind_queue_writer("hand_goal", crease::port_type_of<crease::HandGoal>(), "test", 16);  // force_controller reads 16
    if (o_.with_contact) add_contact();
    if (o_.with_force) add_force();
    if (o_.with_contact) {
      contact_r_ = crease::rt::LatestReader<crease::ContactState>(ports.find_latest("contact_state"));
      events_r_ = ports.bind_queue_reader("contact_event", crease::port_type_of<crease::ContactEvent>(), "test", 64);  // contact_controller writes 64
    }
    if (o_.with_force) rebind_force_readers();
  }

  [[nodiscard]] bool right() const { return o_.side == robot::Side::right; }
  static robot::Side other(robot::Side s) { return s == robot::Side::right ? robot::Side::left : robot::Side::right; }

  void add_contact() {
    // The side's tactile sensor unless the test names one.
    std::string params = "{";
    if (o_.contact_params.find("tactile: ") == std::string::npos) params += right() ? "tactile: taxels, " : "tactile: pst, ";
    params += o_.contact_params + "}";
    crease::InstanceSpec s;
    s.name = "contact";
    s.library = "contact_controller";
    s.loop = "control";
    s.order = 20;
    s.params = crease::Params(YAML::Load(params), "hand_world.yaml", "contact.params");
    host_.add_instance(s);
  }
  void add_force() {
    std::string params = std::string("{side: ") + (right() ? "right" : "left") + ", robot: " + CREASE_SOURCE_DIR +
                         "/config/robot/crease_robot.yaml, default_stiffness: " + std::to_string(o_.stiffness);
    if (o_.force_params.find("start: ") == std::string::npos) params += ", start: hold";  // the hand held from the start
    if (!o_.force_params.empty()) params += ", " + o_.force_params;
    params += "}";
    crease::InstanceSpec s;
    s.name = "force";
    s.library = "force_controller";
    s.loop = "control";
    s.order = 30;
    s.params = crease::Params(YAML::Load(params), "hand_world.yaml", "force.params");
    host_.add_instance(s);
  }
  void rebind_force_readers() {
    auto& ports = host_.ports();
    command_r_ = crease::rt::LatestReader<crease::HandCommand>(ports.find_latest("hand_command"));
    status_r_ = crease::rt::LatestReader<crease::HandControlStatus>(ports.find_latest("hand_control_status"));
    if (force_events_r_ == nullptr)  // force_controller writes 64
      force_events_r_ = ports.bind_queue_reader("hand_control_event", crease::port_type_of<crease::HandControlEvent>(), "test", 64);
  }

  // A hot-swap of the force controller for a new instance of the same library, at a cycle
  // boundary, its state carried (save_state / load_state).
  void swap_force() { host_.swap("force", "force_controller"); }
  void swap_contact() { host_.swap("contact", "contact_controller"); }
  void reload_contact() {
    host_.unload("contact");
    add_contact();
    contact_r_ = crease::rt::LatestReader<crease::ContactState>(host_.ports().find_latest("contact_state"));
  }
  // The failing variant: the force controller unloaded and loaded anew, nothing carried.
  void reload_force() {
    host_.unload("force");
    add_force();
    rebind_force_readers();
  }

  // The arm follows PATH from its start at SPEED (mm/s); STOP_ON_CONTACT: it decelerates at
  // decel_mm_s2 from the cycle contact_state first reports a contact.
  void follow(ArmPath path, double speed_mm_s, bool stop_on_contact) {
    path_ = std::move(path);
    s_mm_ = 0;
    v_ = speed_mm_s;
    v_cmd_ = speed_mm_s;
    stop_on_contact_ = stop_on_contact;
    stopped_cycle_ = -1;
  }
  // A straight path of the index pad from FROM to TO, IK every step_mm from the current arm.
  // The tool's point where the arm is on its path now (its commanded pad point).
  [[nodiscard]] Vec3 here() const { return path_.q.empty() ? o_.start : path_.point(s_mm_); }
  ArmPath line(Vec3 from, Vec3 to, double step_mm = 0.25) {
    ArmPath path;
    path.step_mm = step_mm;
    const double len = sheet::norm(to - from);
    const int n = std::max(1, static_cast<int>(std::ceil(len / step_mm)));
    path.step_mm = len / n;
    ArmQ guess = q_;
    for (int i = 0; i <= n; ++i) {
      const Vec3 p = from + (static_cast<double>(i) / n) * (to - from);
      guess = ik_.solve("ffpad", p, palm_, hand_q_, guess);
      path.q.push_back(guess);
      path.p.push_back(p);
    }
    return path;
  }

  // One control cycle and one world step.
  void cycle() {
    const std::int64_t t = t0_ + static_cast<std::int64_t>(k_) * 1'000'000;
    publish_sensors(t);
    {
      crease::rt::ScopedRtMark rt;  // only the loop's cycle counts
      const crease::rt::CycleClock clock{k_, t, t, 1'000'000};
      loop_->run_cycle_rt(clock);
    }
    if (o_.with_contact) {
      contact_r_.poll();
      crease::ContactEvent e;
      while (events_r_->try_pop(&e)) events_.push_back(e);
    }
    if (o_.with_force) {
      const auto info = command_r_.poll();
      status_r_.poll();
      crease::HandControlEvent fe;
      while (force_events_r_->try_pop(&fe)) force_events_.push_back(fe);
      if (info.has_data()) {
        const crease::HandCommand& c = command_r_.value();
        if (c.enable != 0) {
          for (int j = 0; j < robot::kHandJoints; ++j) {
            max_cmd_jump_ = std::max(max_cmd_jump_, std::fabs(static_cast<double>(c.target_rad[j]) - target_[j]) *
                                                        (commanded_ ? 1.0 : 0.0));
            target_[j] = c.target_rad[j];
            stiffness_[j] = c.stiffness_nm_per_rad[j];
          }
          commanded_ = true;
        } else {
          stiffness_.fill(0.0);  // enable 0: hold with zero stiffness (drivers/README.md §3)
        }
      }
    }
    move_arm();
    world_->command_arm_rt(o_.side, q_);
    world_->command_hand_rt(o_.side, target_, stiffness_);
    world_->command_arm_rt(other(o_.side), q_other_);
    world_->step_rt();
    ++k_;
    if (o_.with_contact && first_contact_cycle_ < 0 && contact_r_.value().in_contact != 0) first_contact_cycle_ = k_ - 1;
    if (first_world_contact_step_ < 0 && tip().contact != 0) {
      first_world_contact_step_ = static_cast<long>(k_ - 1);
      s_at_world_contact_mm_ = s_mm_;
    }
    if (observer_) observer_();
  }
  void run(double seconds) {
    const auto n = static_cast<long>(std::lround(seconds * 1000.0));
    for (long i = 0; i < n; ++i) cycle();
  }
  // Runs until PRED or SECONDS; true when PRED held.
  bool run_until(const std::function<bool()>& pred, double seconds) {
    const auto n = static_cast<long>(std::lround(seconds * 1000.0));
    for (long i = 0; i < n; ++i) {
      cycle();
      if (pred()) return true;
    }
    return false;
  }

  void send(const crease::HandGoal& g) { REQUIRE(goal_w_->try_push(&g)); }
  static crease::HandGoal force_goal(double f_n, double ramp_s, std::uint8_t fingers = 0, std::uint32_t id = 1) {
    crease::HandGoal g;
    g.mode = crease::HandMode::force;
    g.force_n = static_cast<float>(f_n);
    g.ramp_s = static_cast<float>(ramp_s);
    g.fingers = fingers;
    g.id = id;
    return g;
  }

  // The index pad descends from the start at SPEED until contact stops it; returns whether the
  // contact controller reported a contact within SECONDS. The arm waits for the controller to
  // arm (theta_ref captured) first.
  bool approach(double speed_mm_s = 20.0, double depth_mm = 12.0, double seconds = 2.0) {
    if (o_.with_contact) REQUIRE(run_until([&] { return contact().armed != 0; }, 1.0));
    const Vec3 to{o_.start.x, o_.start.y, o_.start.z - depth_mm};
    follow(line(o_.start, to), speed_mm_s, true);
    return run_until([&] { return contact().in_contact != 0; }, seconds);
  }

  // Truth.
  [[nodiscard]] const World& world() const { return *world_; }
  [[nodiscard]] const WorldFingertip& tip(int f = 0) const { return world_->state().hand[me_].tip[f]; }
  [[nodiscard]] double force_n(int f = 0) const { return tip(f).contact != 0 ? tip(f).normal_force_n : 0.0; }
  // What the controllers published.
  [[nodiscard]] const crease::ContactState& contact() const { return contact_r_.value(); }
  [[nodiscard]] const crease::HandControlStatus& status() const { return status_r_.value(); }
  [[nodiscard]] const crease::HandCommand& command() const { return command_r_.value(); }
  [[nodiscard]] const std::vector<crease::ContactEvent>& contact_events() const { return events_; }
  [[nodiscard]] const std::vector<crease::HandControlEvent>& force_events() const { return force_events_; }
  [[nodiscard]] crease::PluginHost& host() { return host_; }
  [[nodiscard]] long cycles() const { return static_cast<long>(k_); }
  [[nodiscard]] long first_contact_cycle() const { return first_contact_cycle_; }
  [[nodiscard]] long first_world_contact_step() const { return first_world_contact_step_; }
  [[nodiscard]] long stopped_cycle() const { return stopped_cycle_; }
  [[nodiscard]] double arm_s_mm() const { return s_mm_; }
  // How far the arm moved along its path since the world's first contact (mm).
  [[nodiscard]] double travel_since_contact_mm() const { return s_mm_ - s_at_world_contact_mm_; }
  [[nodiscard]] const ArmPath& path() const { return path_; }
  [[nodiscard]] const HandQ& commanded_targets() const { return target_; }
  // The largest change of a commanded joint target between two cycles since the last reset.
  [[nodiscard]] double max_command_jump_rad() const { return max_cmd_jump_; }
  void reset_command_jump() { max_cmd_jump_ = 0; }

  // Fault injection: edit the sensors' values before they are written, or withhold them.
  std::function<void(crease::HandState&)> edit_hand;
  std::function<void(crease::Tactile&)> edit_tactile;
  bool withhold_hand = false, withhold_tactile = false;
  std::function<void()> observer_;  // after every cycle
  double decel_mm_s2 = 1000.0;      // the arm stand-in's stop

 private:
  void publish_sensors(std::int64_t t) {
    const WorldHand& h = world_->state().hand[me_];
    crease::HandState hs;
    hs.timestamp_ns = t;
    hs.device_time_us = static_cast<std::uint32_t>(k_ * 1000);
    hs.valid = (1u << 20) - 1;
    for (int j = 0; j < robot::kHandJoints; ++j) {
      double q = h.joint_rad[j];
      if (o_.joint_noise_rad > 0) q += o_.joint_noise_rad * noise_.gaussian();
      hs.position_rad[j] = static_cast<float>(std::round(q * 1e4) * 1e-4);  // the wire's unit
    }
    if (!right()) {
      pst_.pst_rt(h, 0.001, hs.pressure_kpa);
      hs.pressure_valid = 0x1F;
    }
    hs.fresh = 1;
    hs.health = crease::DeviceHealth::ok;
    hs.safe_state = 0;
    if (edit_hand) edit_hand(hs);
    if (!withhold_hand) hand_w_->write(&hs, t);
    if (right()) {
      if (k_ % 4 == 0) {  // 250 Hz
        tactile_.timestamp_ns = t;
        tactile_.device_time_us = static_cast<std::uint32_t>(k_ * 1000);
        ++tactile_.sample_counter;
        tactile_.valid = 0x1F;
        tactile_.health = crease::DeviceHealth::ok;
        taxels_.taxels_rt(h, tactile_.pressure_kpa);
      }
      tactile_.fresh = k_ % 4 == 0 ? 1 : 0;
      tactile_.age_ns = t - tactile_.timestamp_ns;
      crease::Tactile out = tactile_;
      if (edit_tactile) edit_tactile(out);
      if (!withhold_tactile) tactile_w_->write(&out, t);
    }
  }

  void move_arm() {
    if (path_.q.empty()) return;
    if (stop_on_contact_ && stopped_cycle_ < 0 && o_.with_contact && contact_r_.value().in_contact != 0) {
      stopped_cycle_ = static_cast<long>(k_);
      v_cmd_ = 0;
    }
    const double dv = decel_mm_s2 * 0.001;
    v_ = v_ > v_cmd_ ? std::max(v_cmd_, v_ - dv) : std::min(v_cmd_, v_ + dv);
    s_mm_ = std::min(path_.length_mm(), s_mm_ + v_ * 0.001);
    q_ = path_.at(s_mm_);
  }

  Options o_;
  int me_;
  ArmIk ik_;
  crease::world::TactileModel pst_, taxels_, noise_;
  crease::PluginHost host_;
  crease::Loop* loop_ = nullptr;
  std::unique_ptr<World> world_;
  KDL::Rotation palm_;
  HandQ hand_q_{}, target_{}, stiffness_{};
  ArmQ q_{}, q_other_{};
  crease::rt::LatestChannel* hand_w_ = nullptr;
  crease::rt::LatestChannel* tactile_w_ = nullptr;
  crease::rt::QueueChannel* goal_w_ = nullptr;
  crease::rt::QueueChannel* events_r_ = nullptr;
  crease::rt::QueueChannel* force_events_r_ = nullptr;
  crease::rt::LatestReader<crease::ContactState> contact_r_;
  crease::rt::LatestReader<crease::HandCommand> command_r_;
  crease::rt::LatestReader<crease::HandControlStatus> status_r_;
  crease::Tactile tactile_{};
  std::vector<crease::ContactEvent> events_;
  std::vector<crease::HandControlEvent> force_events_;
  ArmPath path_;
  double s_mm_ = 0, v_ = 0, v_cmd_ = 0, s_at_world_contact_mm_ = 0;
  bool stop_on_contact_ = false;
  long stopped_cycle_ = -1;
  std::uint64_t k_ = 0;
  std::int64_t t0_ = 1'000'000'000;
  long first_contact_cycle_ = -1;
  long first_world_contact_step_ = -1;
  bool commanded_ = false;
  double max_cmd_jump_ = 0;
};

}  // namespace hand_world
