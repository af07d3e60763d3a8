// crease-bench control: the 1 kHz control loop's controller stage.
//
// (1) Inverse kinematics: the same random reachable poses (random arm and hand
// angles within the URDF's limits, every tool frame, both arms) solved from the same rest
// posture by ours (robot_model ArmIk::solve: damped least squares, limits, null space) and by
// KDL's ChainIkSolverPos_LMA on the same world -> flange chain, in the same run: microseconds
// per call, how many converged (to 0.1 mm / 0.1 mrad, scored by robot_model's forward
// kinematics), and ours per tracking call (ArmIk::track, warm from the last cycle). (2) The
// controller stage: two arm_motion controllers (ArmMotion, what the plugin's update runs) with
// arms that follow their commands, through a sequence of motions (goals arriving, solved ahead,
// running, a stop on a contact onset, holding), and both hands' contact and force controllers
// (bench_control_hands.h: approach, contact, C_force at 0.5 N and 2 N, lift-off, over and over):
// per cycle p50 / p99 / max of the whole stage, and of the arms and the hands apart, against the
// issue's target (the whole stage p99 <= 20 us) and KDL's LMA per call. The drivers are not in
// it (their cost is the bus's: crease-bench bus).
#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <kdl/chainiksolverpos_lma.hpp>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "bench_control_hands.h"
#include "bench_registry.h"
#include "bench_util.h"
#include "plugins/arm_motion/arm_motion.h"
#include "plugins/robot_model/arm_ik.h"
#include "plugins/sim_world/world_config.h"
#include "rt/rt_setup.h"

namespace {

using namespace crease;
using namespace crease::robot;
using Clock = std::chrono::steady_clock;
using Joints = std::array<double, kArmJoints>;
using Hand = std::array<double, kHandJoints>;

double us_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5));
  return v[i];
}

double rot_angle(const KDL::Rotation& a, const KDL::Rotation& b) {
  double f = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f += (a(i, j) - b(i, j)) * (a(i, j) - b(i, j));
  return 2.0 * std::asin(std::min(1.0, std::sqrt(f) / (2.0 * std::sqrt(2.0))));
}
double dist(const KDL::Vector& a, const KDL::Vector& b) { return std::sqrt(KDL::dot(a - b, a - b)); }

// The right and left rest postures of arm_motion's parameters (arm_motion_params.cpp).
Joints rest_of(Side s) {
  return s == Side::right ? Joints{-0.628, -0.341, -0.263, 0.958, 0.942, 1.243, 2.589}
                          : Joints{-0.908, -0.596, 0.306, 0.958, 0.708, 1.167, 3.030};
}

struct IkFigures {
  double ours_us = 0, kdl_us = 0, track_us = 0;
  int ours_ok = 0, kdl_ok = 0, kdl_reached = 0, n = 0;
};

IkFigures bench_ik(RobotModel& m, int poses) {
  IkFigures f;
  std::mt19937 rng(20261202);
  std::vector<double> ours, kdl, track;
  for (int s = 0; s < kSides; ++s) {
    const Side side = static_cast<Side>(s);
    ArmIk::Options o;
    o.rest_rad = rest_of(side);
    ArmIk ik(m, side, o);
    // KDL's LMA with its defaults (eps 1e-5, 500 iterations, eps_joints 1e-15) on the same chain.
    KDL::ChainIkSolverPos_LMA lma(ik.arm_chain());
    KDL::JntArray q0(kArmJoints), qk(kArmJoints);
    for (int i = 0; i < poses; ++i) {
      Joints q_true{};
      for (int j = 0; j < kArmJoints; ++j) {
        const double c = 0.5 * (ik.lower()[j] + ik.upper()[j]), h = 0.45 * (ik.upper()[j] - ik.lower()[j]);
        q_true[j] = std::uniform_real_distribution<double>(c - h, c + h)(rng);
      }
      Hand hand{};
      for (int j = 0; j < kHandJoints; ++j) {
        const auto& info = m.hand_joints(side)[j];
        hand[j] = std::uniform_real_distribution<double>(info.lower_rad, info.upper_rad)(rng);
      }
      const ToolFrame tool = static_cast<ToolFrame>(i % kToolFrames);
      (void)ik.set_tool(tool, q_true, hand);
      const KDL::Frame target = ik.tool_pose(q_true);
      const auto score = [&](const Joints& q) {
        KDL::Frame got;
        (void)m.tool_pose_m(side, tool, q, hand, got);
        return dist(got.p, target.p) < 1e-4 && rot_angle(got.M, target.M) < 1e-4;
      };
      // Ours.
      Joints q{};
      auto t0 = Clock::now();
      (void)ik.solve(target, o.rest_rad, q);
      ours.push_back(us_since(t0));
      bool in_limits = true;
      for (int j = 0; j < kArmJoints; ++j) in_limits = in_limits && q[j] >= ik.lower()[j] && q[j] <= ik.upper()[j];
      f.ours_ok += score(q) && in_limits;
      // KDL's LMA: the flange's pose for that tool frame, from the same seed.
      const KDL::Frame flange_target = target * ik.tool_offset().Inverse();
      for (int j = 0; j < kArmJoints; ++j) q0(j) = o.rest_rad[j];
      t0 = Clock::now();
      (void)lma.CartToJnt(q0, flange_target, qk);
      kdl.push_back(us_since(t0));
      Joints qkdl{};
      bool kdl_in = true;
      for (int j = 0; j < kArmJoints; ++j) {
        qkdl[j] = qk(j);
        kdl_in = kdl_in && qk(j) >= ik.lower()[j] && qk(j) <= ik.upper()[j];
      }
      f.kdl_reached += score(qkdl);
      f.kdl_ok += score(qkdl) && kdl_in;
      // Ours tracking: a 0.1 mm step from the solution (one control cycle at 100 mm/s).
      const KDL::Frame next(target.M, target.p + KDL::Vector(1e-4, 0, 0));
      Joints qt = q;
      t0 = Clock::now();
      (void)ik.track(next, qt);
      track.push_back(us_since(t0));
      ++f.n;
    }
  }
  f.ours_us = percentile(ours, 0.5);
  f.kdl_us = percentile(kdl, 0.5);
  f.track_us = percentile(track, 0.5);
  std::printf("IK, %d random reachable poses (both arms, every tool frame), from the rest posture:\n", f.n);
  std::printf("  ours (ArmIk::solve)          median %7.1f us  mean %7.1f us  p99 %8.1f us  reached %d/%d, all "
              "within the limits\n",
              f.ours_us, [&] { double s = 0; for (double x : ours) s += x; return s / ours.size(); }(),
              percentile(ours, 0.99), f.ours_ok, f.n);
  std::printf("  KDL ChainIkSolverPos_LMA     median %7.1f us  mean %7.1f us  p99 %8.1f us  reached %d/%d, "
              "%d of them within the limits\n",
              f.kdl_us, [&] { double s = 0; for (double x : kdl) s += x; return s / kdl.size(); }(),
              percentile(kdl, 0.99), f.kdl_reached, f.n, f.kdl_ok);
  std::printf("  ours tracking (ArmIk::track) median %7.2f us  p99 %7.2f us (a 0.1 mm step, warm)\n", f.track_us,
              percentile(track, 0.99));
  return f;
}

// Where the controller stage's arms work: creased's parked posture (sim_world's, each index pad
// 300 mm over the table), inside arm_motion's workspace box. (From the rest posture above, the
// arms hanging 1 m over the table, every goal lay outside it and was refused: the stage then
// timed no arm motion at all.)
Joints parked_of(Side s) {
  Joints q{};
  for (int j = 0; j < kArmJoints; ++j) q[j] = crease::world::kParkedArmDeg[s == Side::right ? 0 : 1][j] * std::numbers::pi / 180.0;
  return q;
}

// One arm with an arm that follows its command (a perfect drive).
struct Arm {
  Arm(RobotModel& m, Side s) : side(s), q(parked_of(s)) {
    arm_motion::MotionParams p;
    p.ik.rest_rad = rest_of(s);
    motion = std::make_unique<arm_motion::ArmMotion>(m, s, p);
    contact.armed = contact.healthy = 1;
  }
  void inputs(std::int64_t now) {
    state.timestamp_ns = now;
    state.valid = 0x7f;
    state.fresh = 1;
    state.drive_state = 4;
    state.health = DeviceHealth::ok;
    for (int j = 0; j < kArmJoints; ++j) state.position_rad[j] = static_cast<float>(q[j]);
    hand.timestamp_ns = now;
    hand.health = DeviceHealth::ok;
    contact.timestamp_ns = now;
    in.now_ns = now;
    in.arm = &state;
    in.hand = &hand;
    in.contact = &contact;
  }
  void follow() {
    for (int j = 0; j < kArmJoints; ++j) q[j] = motion->command().position_rad[j];
  }
  Side side;
  Joints q;
  std::unique_ptr<arm_motion::ArmMotion> motion;
  ArmState state;
  HandState hand;
  ContactState contact;
  arm_motion::CycleInputs in;
};

ArmGoal goal(const KDL::Frame& pose, std::uint32_t id, ToolFrame tool) {
  ArmGoal g;
  g.id = id;
  g.tool = static_cast<std::uint8_t>(tool);
  g.point_count = 1;
  g.speed_mm_s = 100;
  g.accel_mm_s2 = 1000;
  g.angular_speed_rad_s = 1;
  g.angular_accel_rad_s2 = 10;
  g.stop_accel_mm_s2 = 2000;
  for (int i = 0; i < 3; ++i) g.position_mm[0][i] = 1000.0 * pose.p(i);
  pose.M.GetQuaternion(g.orientation[0][0], g.orientation[0][1], g.orientation[0][2], g.orientation[0][3]);
  return g;
}

// The controller stage of one cycle: the arms, then the hands; each part's time added to ARM_US
// and HAND_US.
void stage_cycle(std::vector<Arm>& arms, const std::vector<const ArmGoal*>& goals, std::vector<bench::BenchHand>& hands,
                 double& arm_us, double& hand_us) {
  const auto t0 = Clock::now();
  for (std::size_t a = 0; a < arms.size(); ++a) {
    if (goals[a] != nullptr) arms[a].motion->on_goal(*goals[a], arms[a].in, nullptr);
    (void)arms[a].motion->step(arms[a].in);
  }
  const auto t1 = Clock::now();
  for (bench::BenchHand& h : hands) h.step();
  const auto t2 = Clock::now();
  arm_us = std::chrono::duration<double, std::micro>(t1 - t0).count();
  hand_us = std::chrono::duration<double, std::micro>(t2 - t1).count();
}

struct StageTimes {
  std::vector<double> cycle_us, arm_us, hand_us;
};

StageTimes bench_stage(RobotModel& m, double seconds, bool paced) {
  std::vector<Arm> arms;
  arms.emplace_back(m, Side::right);
  arms.emplace_back(m, Side::left);
  const std::string robot_yaml = std::string(CREASE_SOURCE_DIR) + "/config/robot/crease_robot.yaml";
  std::vector<bench::BenchHand> hands;
  hands.emplace_back(Side::right, robot_yaml);
  hands.emplace_back(Side::left, robot_yaml);
  StageTimes times;
  const int cycles = static_cast<int>(seconds * 1000);
  times.cycle_us.reserve(static_cast<std::size_t>(cycles));
  times.arm_us.reserve(static_cast<std::size_t>(cycles));
  times.hand_us.reserve(static_cast<std::size_t>(cycles));
  std::int64_t now = 1'000'000'000;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> off(-0.04, 0.04);
  std::vector<ArmGoal> pending(2);
  std::uint32_t id = 0;
  int onsets = 0;
  // Paced at 1 kHz like the control loop (absolute deadlines), SCHED_FIFO where permitted, with
  // the real-time setup creased applies on the robot (config/robot.yaml: memory locked,
  // daemon.cpu_dma_latency_us 0, which cyclictest also holds), each step printed.
  sched_param sp{};
  sp.sched_priority = 80;
  const bool fifo = paced && pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
  crease::rt::DmaLatencyRequest dma;
  if (paced) {
    for (const crease::rt::SetupStep& st : {crease::rt::lock_memory(64u << 20), dma.request(0)})
      std::printf("  paced run: %s: %s%s\n", st.what.c_str(),
                  st.applied ? "applied" : "not applied: ", st.why.c_str());
  }
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (int c = 0; c < cycles; ++c) {
    next.tv_nsec += 1'000'000;
    if (next.tv_nsec >= 1'000'000'000) {
      next.tv_nsec -= 1'000'000'000;
      ++next.tv_sec;
    }
    if (paced) clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    now += 1'000'000;
    std::vector<const ArmGoal*> goals(2, nullptr);
    for (std::size_t a = 0; a < arms.size(); ++a) {
      Arm& arm = arms[a];
      arm.inputs(now);
      const auto st = arm.motion->status().state;
      const bool idle = st != ArmMotionStatus::checking && st != ArmMotionStatus::running &&
                        st != ArmMotionStatus::stopping;
      if (idle && c % 50 == 0 && c > 0) {  // a new goal near the rest pose, every other one stopping on contact
        Joints qc{};
        for (int j = 0; j < kArmJoints; ++j) qc[j] = arm.motion->state().q_cmd[j];
        const ToolFrame tool = (id % 2 == 0) ? ToolFrame::ff_pad : ToolFrame::palm_front;
        Hand h{};
        KDL::Frame rest;
        (void)m.tool_pose_m(arm.side, tool, parked_of(arm.side), h, rest);
        pending[a] = goal(KDL::Frame(KDL::Rotation::RotZ(off(rng)) * rest.M,
                                     rest.p + KDL::Vector(off(rng), off(rng), off(rng))),
                          ++id, tool);
        pending[a].stop_on = id % 2 == 0 ? ArmGoal::contact_onset : ArmGoal::stop_none;
        goals[a] = &pending[a];
      }
      if (st == ArmMotionStatus::running && arm.motion->state().stop_on == ArmGoal::contact_onset &&
          arm.motion->status().progress > 0.5f) {
        ++arm.contact.onsets;  // a contact half way
        arm.contact.fingers = 1;
        ++onsets;
      }
    }
    for (bench::BenchHand& h : hands) h.sense(now);
    double arm_us = 0, hand_us = 0;
    const auto t0 = Clock::now();
    stage_cycle(arms, goals, hands, arm_us, hand_us);
    times.cycle_us.push_back(us_since(t0));
    times.arm_us.push_back(arm_us);
    times.hand_us.push_back(hand_us);
    for (Arm& arm : arms) arm.follow();
    for (bench::BenchHand& h : hands) h.follow();
  }
  std::uint32_t accepted = 0, refused = 0;
  for (const Arm& a : arms) {
    accepted += a.motion->status().goals_accepted;
    refused += a.motion->status().goals_refused;
  }
  if (accepted == 0) {  // the stage would time refusals, not motion: say so, with why
    std::printf("WARNING: no arm goal was accepted; refusals by ArmMotionReason:");
    for (const Arm& a : arms)
      for (int r = 0; r < kArmMotionReasons; ++r)
        if (a.motion->status().reasons[r] != 0) std::printf(" %d:%u", r, a.motion->status().reasons[r]);
    std::printf("\n");
  }
  sp.sched_priority = 0;
  (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &sp);
  std::printf("controller stage, 2 arms and 2 hands, %d cycles %s (%s): arms %u goals accepted, %u refused, %d contact "
              "stops; hands (right, left) %llu / %llu contacts, %llu / %llu force goals, %llu / %llu settled, at most %.2f / %.2f N\n",
              cycles, paced ? "paced at 1 kHz" : "back to back (caches hot)", fifo ? "SCHED_FIFO 80" : "SCHED_OTHER",
              accepted, refused, onsets, static_cast<unsigned long long>(hands[0].onsets()),
              static_cast<unsigned long long>(hands[1].onsets()), static_cast<unsigned long long>(hands[0].force_goals()),
              static_cast<unsigned long long>(hands[1].force_goals()),
              static_cast<unsigned long long>(hands[0].settled_holds()),
              static_cast<unsigned long long>(hands[1].settled_holds()), hands[0].max_force_n(), hands[1].max_force_n());
  return times;
}

int run_control(int argc, char** argv) {
  const int poses = static_cast<int>(bench::arg_double(argc, argv, "--poses", 500));
  const double seconds = bench::arg_double(argc, argv, "--seconds", 10);
  RobotModel m = RobotModel::load(std::string(CREASE_SOURCE_DIR) + "/config/robot/crease_robot.yaml");
  const IkFigures ik = bench_ik(m, poses);
  struct Figures {
    double p50, p99, p999, max;
  };
  const auto figures = [](const std::vector<double>& v) {
    return Figures{percentile(v, 0.5), percentile(v, 0.99), percentile(v, 0.999), *std::max_element(v.begin(), v.end())};
  };
  const auto print = [&](const StageTimes& t) {
    const Figures c = figures(t.cycle_us), a = figures(t.arm_us), h = figures(t.hand_us);
    std::printf("  per cycle, whole stage:  p50 %6.2f us  p99 %6.2f us  p99.9 %7.1f us  max %7.1f us   (target p99 <= 20 us)\n",
                c.p50, c.p99, c.p999, c.max);
    std::printf("    arms (goals, path checks, profile, IK):       p50 %6.2f us  p99 %6.2f us  max %7.1f us\n", a.p50, a.p99,
                a.max);
    std::printf("    hands (C_contact, C_force / posture / hold): p50 %6.2f us  p99 %6.2f us  max %7.1f us\n", h.p50, h.p99,
                h.max);
    std::printf("    vs KDL ChainIkSolverPos_LMA, one call from the rest posture: median %.1f us\n", ik.kdl_us);
    return std::array<Figures, 3>{c, a, h};
  };
  const auto hot = print(bench_stage(m, seconds, false));
  const auto paced = print(bench_stage(m, seconds, true));
  std::printf("control: cycle_p99_us=%.2f cycle_p50_us=%.2f cycle_max_us=%.1f hand_p99_us=%.2f arm_p99_us=%.2f "
              "hot_p99_us=%.2f hot_p50_us=%.2f hot_hand_p99_us=%.2f ik_us=%.1f kdl_lma_us=%.1f ik_track_us=%.2f ik_ok=%d "
              "kdl_lma_ok=%d ik_poses=%d\n",
              paced[0].p99, paced[0].p50, paced[0].max, paced[2].p99, paced[1].p99, hot[0].p99, hot[0].p50, hot[2].p99,
              ik.ours_us, ik.kdl_us, ik.track_us, ik.ours_ok, ik.kdl_ok, ik.n);
  return 0;
}

}  // namespace

CREASE_BENCH(control, "control stage: arm IK vs KDL's LMA, the per-cycle cost of both arms' and both hands' controllers", run_control);
