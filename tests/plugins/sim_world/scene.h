// Test support for the world's physics tests: the shipped robot, arm inverse kinematics to
// place a hand's tool frame (KDL's Levenberg-Marquardt solver on the arm's chain, the hand's
// angles fixed), and the poses the scenes use. Non-RT; the scenes call the world's RT step.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <memory>
#include <numbers>
#include <string>

#include "plugins/robot_model/robot_model.h"
#include "plugins/sim_world/reference_poses.h"
#include "plugins/sim_world/sim_world.h"
#include "plugins/sim_world/world_config.h"

namespace scene {

using namespace crease;
using namespace crease::world;
using Vec3 = crease::sheet::Vec3;
using ArmQ = World::ArmJoints;
using HandQ = World::HandJoints;

inline const robot::RobotModel& robot_model() {
  static const robot::RobotModel m =
      robot::RobotModel::load(std::string(CREASE_SOURCE_DIR) + "/config/robot/crease_robot.yaml");
  return m;
}

inline double deg(double d) { return d * std::numbers::pi / 180.0; }

// Hand joint indices (drivers/README.md §3), index_out(), pinch_hand(): reference_poses.h.
using namespace poses::joints;

// A rotation from its z axis and a vector near its x axis (plugins/sim_world/reference_poses.h).
inline KDL::Rotation frame_from_z_x(Vec3 z, Vec3 x_hint) {
  return poses::frame_from_z_x(KDL::Vector(z.x, z.y, z.z), KDL::Vector(x_hint.x, x_hint.y, x_hint.z));
}

// Places a tool link of one side's hand at a pose by moving the arm only.
class ArmIk {
 public:
  ArmIk(const robot::RobotModel& m, robot::Side side) {
    const std::string prefix = m.params().side(side).prefix;
    REQUIRE(m.tree().getChain("world", prefix + "flange", chain_));
    REQUIRE(chain_.getNrOfJoints() == robot::kArmJoints);
    solver_ = std::make_unique<KDL::ChainIkSolverPos_LMA>(chain_, 1e-9, 1000);
    fk_ = std::make_unique<KDL::ChainFkSolverPos_recursive>(chain_);
    kin_ = std::make_unique<SideKinematics>(m, side);
    flange_ = kin_->link_index(prefix + "flange");
    prefix_ = prefix;
    const auto& j = m.arm_joints(side);
    for (int i = 0; i < robot::kArmJoints; ++i) {
      lo_[i] = j[i].lower_rad;
      hi_[i] = j[i].upper_rad;
    }
  }

  // Arm angles putting link TOOL's origin (without prefix) at p_mm with the palm turned to
  // PALM, the hand at HAND, starting from GUESS (then, if that ends outside the limits or short
  // of the pose, from a fixed grid of guesses over the shoulder, elbow and wrist: the first
  // within both). Fails the test when none reaches it within TOL_MM (0.01 mm) and kTolRad within
  // the limits.
  ArmQ solve(const std::string& tool, Vec3 p_mm, const KDL::Rotation& palm, const HandQ& hand, const ArmQ& guess,
             double tol_mm = 0.01) {
    Attempt a = attempt(tool, p_mm, palm, hand, guess);
    for (double s1 : {0.0, 0.5, -0.5, 1.0, -1.0})
      for (double s2 : {0.5, 0.2, 0.8, -0.3, 1.2})
        for (double e1 : {1.4, 0.8, 2.0, 2.3})
          for (double w1 : {1.2, 0.6, -0.6, 1.6}) {
            if (a.within_limits && a.reached(tol_mm)) break;
            a = attempt(tool, p_mm, palm, hand, {s1, s2, 0.0, e1, 0.0, w1, 0.0});
          }
    if (!(a.reached(tol_mm) && a.within_limits))
      std::printf("ik: %s at (%.1f, %.1f, %.1f) mm: rc %d err %.4f mm %.2g rad, within limits %d\n", tool.c_str(), p_mm.x,
                  p_mm.y, p_mm.z, a.rc, a.err_mm, a.err_rad, static_cast<int>(a.within_limits));
    REQUIRE(a.err_mm < tol_mm);
    REQUIRE(a.err_rad < kTolRad);
    for (int i = 0; i < robot::kArmJoints; ++i) {
      REQUIRE(a.q[i] >= lo_[i]);
      REQUIRE(a.q[i] <= hi_[i]);
    }
    return a.q;
  }

  // The solver's answer without failing the test: the angles (a joint past a limit turned by
  // 2 pi when that brings it within), how far the tool ended from the goal, and whether every
  // joint is within its limits.
  struct Attempt {
    ArmQ q{};
    double err_mm = 0;
    double err_rad = 0;  // the flange's turn from the goal's
    bool within_limits = false;
    int rc = 0;
    [[nodiscard]] bool reached(double tol_mm) const { return err_mm < tol_mm && err_rad < kTolRad; }
  };
  static constexpr double kTolRad = 1e-4;  // the palm's orientation: 0.006 deg
  Attempt attempt(const std::string& tool, Vec3 p_mm, const KDL::Rotation& palm, const HandQ& hand, const ArmQ& guess) {
    const int t = kin_->link_index(prefix_ + tool), pl = kin_->link_index(prefix_ + "palm");
    REQUIRE(t >= 0);
    kin_->update_rt(guess, hand);
    const KDL::Frame world_palm = poses::to_kdl_frame(kin_->link_pose(pl));
    const KDL::Frame palm_tool = world_palm.Inverse() * poses::to_kdl_frame(kin_->link_pose(t));
    const KDL::Frame palm_flange = world_palm.Inverse() * poses::to_kdl_frame(kin_->link_pose(flange_));
    const KDL::Vector p = KDL::Vector(p_mm.x, p_mm.y, p_mm.z) / 1000.0 - palm * palm_tool.p;
    const KDL::Frame goal = KDL::Frame(palm, p) * palm_flange;
    KDL::JntArray q0(robot::kArmJoints), q(robot::kArmJoints);
    for (int i = 0; i < robot::kArmJoints; ++i) q0(i) = guess[i];
    Attempt a;
    a.rc = solver_->CartToJnt(q0, goal, q);
    a.within_limits = true;
    for (int i = 0; i < robot::kArmJoints; ++i) {
      double v = q(i);
      constexpr double kTurn = 2.0 * std::numbers::pi;
      if (v > hi_[i] && v - kTurn >= lo_[i]) v -= kTurn;
      if (v < lo_[i] && v + kTurn <= hi_[i]) v += kTurn;
      a.q[i] = v;
      a.within_limits = a.within_limits && v >= lo_[i] && v <= hi_[i];
    }
    KDL::Frame reached;
    REQUIRE(fk_->JntToCart(q, reached) >= 0);
    a.err_mm = 1000.0 * (reached.p - goal.p).Norm();
    KDL::Vector axis;
    a.err_rad = std::fabs((reached.M.Inverse() * goal.M).GetRotAngle(axis));
    return a;
  }

 private:
  KDL::Chain chain_;
  std::unique_ptr<KDL::ChainIkSolverPos_LMA> solver_;
  std::unique_ptr<KDL::ChainFkSolverPos_recursive> fk_;
  std::unique_ptr<SideKinematics> kin_;
  int flange_ = -1;
  std::string prefix_;
  ArmQ lo_{}, hi_{};
};

// A first guess of the arm near the workspace over the sheet (elbow bent, hand down).
inline ArmQ arm_guess() { return {0.0, 0.5, 0.0, 1.4, 0.0, 1.2, 0.0}; }

// Only the index finger out: the others bent back to their J3 limit (-15 deg).
using poses::index_out;

// The palm turned forward (+y) and down by BETA (either hand: reference_poses.h).
inline KDL::Rotation palm_forward_down(robot::Side, double beta) { return poses::palm_forward_down(beta); }

// A world with the working hand's tool TOOL at START (palm turned PALM, hand HAND) and the
// other hand parked beside the table; the nominal world unless PARAMS says otherwise.
struct Rig {
  Rig(WorldParams p, const std::string& tool_, Vec3 start, const KDL::Rotation& palm_, const HandQ& hand,
      robot::Side side_ = robot::Side::right)
      : params(std::move(p)), side(side_), ik(robot_model(), side_),
        tool(tool_), palm(palm_), hand_q(hand), last(start) {
    q = ik.solve(tool, start, palm, hand_q, arm_guess());
    // The other arm parked as creased parks it (sim_world's default: its pad 300 mm over the
    // table beside the sheet).
    const int parked = 1 - static_cast<int>(side);
    for (int j = 0; j < robot::kArmJoints; ++j) q_other[j] = world::kParkedArmDeg[parked][j] * std::numbers::pi / 180.0;
    const int me = static_cast<int>(side), them = static_cast<int>(other(side));
    params.initial_arm_rad[me] = q;
    params.initial_arm_rad[them] = q_other;
    params.initial_hand_rad[me] = hand_q;
    params.initial_hand_rad[them] = other_hand;
    world = std::make_unique<World>(robot_model(), params);
    stiffness.fill(params.initial_stiffness_nm_per_rad);
    other_stiffness.fill(params.initial_stiffness_nm_per_rad);
  }
  static robot::Side other(robot::Side s) { return s == robot::Side::right ? robot::Side::left : robot::Side::right; }

  // One step with the tool commanded to P (arm IK from the last solution), the hand at hand_q.
  void step_to(Vec3 p) {
    q = ik.solve(tool, p, palm, hand_q, q);
    world->command_arm_rt(side, q);
    world->command_hand_rt(side, hand_q, stiffness);
    world->command_arm_rt(other(side), q_other);
    world->command_hand_rt(other(side), other_hand, other_stiffness);
    world->step_rt();
  }
  // Steps from the tool's last commanded point to P at SPEED mm/s, then holds for HOLD s.
  void move(Vec3 p, double speed_mm_s, double hold_s = 0.0) {
    const Vec3 from = last;
    const double len = crease::sheet::norm(p - from);
    const int n = std::max(1, static_cast<int>(std::ceil(len / (speed_mm_s * world->params().dt_s))));
    for (int i = 1; i <= n; ++i) {
      last = from + (static_cast<double>(i) / n) * (p - from);
      step_to(last);
    }
    hold(hold_s);
  }
  void hold(double s) {
    const int h = static_cast<int>(std::lround(s / world->params().dt_s));
    for (int i = 0; i < h; ++i) step_to(last);
  }
  // The tool descends at SPEED from where it is until fingertip TIP touches; returns its z.
  double descend_to_contact(int tip, double speed_mm_s, double floor_z) {
    const double dz = speed_mm_s * world->params().dt_s;
    while (last.z > floor_z && world->state().hand[static_cast<int>(side)].tip[tip].contact == 0) {
      last.z -= dz;
      step_to(last);
    }
    return last.z;
  }
  [[nodiscard]] const WorldHand& hand() const { return world->state().hand[static_cast<int>(side)]; }

  WorldParams params;
  robot::Side side;
  ArmIk ik;
  std::string tool;
  KDL::Rotation palm;
  HandQ hand_q{}, other_hand{}, stiffness{}, other_stiffness{};
  ArmQ q{}, q_other{};
  Vec3 last;
  std::unique_ptr<World> world;
};

// The mean position of the sheet's nodes (mm).
inline Vec3 sheet_centroid(const World& w) {
  Vec3 c;
  const auto x = w.sheet().positions();
  for (const Vec3& p : x) c += p;
  return (1.0 / static_cast<double>(x.size())) * c;
}

// The largest stretch of the sheet's grid edges (along u and v) against the flat sheet's
// spacing: 0.1 is 10 %.
inline double max_edge_stretch(const World& w) {
  const auto x = w.sheet().positions();
  const auto& g = w.sheet().grid();
  double worst = 0;
  for (int j = 0; j < g.h; ++j)
    for (int i = 0; i < g.w; ++i) {
      const Vec3 p = x[g.index(i, j)];
      if (i + 1 < g.w) worst = std::max(worst, sheet::norm(x[g.index(i + 1, j)] - p) / g.du - 1.0);
      if (j + 1 < g.h) worst = std::max(worst, sheet::norm(x[g.index(i, j + 1)] - p) / g.dv - 1.0);
    }
  return worst;
}

inline WorldParams nominal() {
  WorldParams p;
  p.randomise = false;
  return p;
}

// Both hands driven at once (the fold and crease scenes).
// One arm and hand driven by a tool pose: arm IK every step (scene.h), hand targets, stiffness.
struct Arm {
  ArmIk ik;
  std::string tool;
  KDL::Rotation palm;
  HandQ q{}, k{};
  ArmQ arm{};
  Vec3 at;
  Arm(robot::Side s, std::string t) : ik(robot_model(), s), tool(std::move(t)) {}

  // A first solution from a few guesses over the shoulder, elbow and wrist (non-RT set-up).
  void solve_first() {
    for (double s1 : {0.0, 0.5, -0.5, 1.0, -1.0})
      for (double s2 : {0.5, 0.2, 0.8, -0.3, 1.2})
        for (double e1 : {1.4, 0.8, 2.0, 2.3})
          for (double w1 : {1.2, 0.6, -0.6, 1.6}) {
            const ArmIk::Attempt t = ik.attempt(tool, at, palm, q, {s1, s2, 0.0, e1, 0.0, w1, 0.0});
            if (t.within_limits && t.reached(0.01)) {
              arm = t.q;
              return;
            }
          }
    FAIL("no arm solution for " << tool << " at " << at.x << " " << at.y << " " << at.z);
  }
};

struct Bimanual {
  WorldParams params;
  Arm r{robot::Side::right, "ffpad"}, l{robot::Side::left, "ffpad"};
  std::unique_ptr<World> world;

  void start() {
    r.solve_first();
    l.solve_first();
    params.initial_arm_rad[0] = r.arm;
    params.initial_arm_rad[1] = l.arm;
    params.initial_hand_rad[0] = r.q;
    params.initial_hand_rad[1] = l.q;
    world = std::make_unique<World>(robot_model(), params);
  }
  // One step with both tools commanded where they are now (IK from the last solution, within
  // 0.5 mm: the turned pinch passes near the arm's singular configurations).
  void step() {
    for (Arm* a : {&r, &l}) {
      a->arm = a->ik.solve(a->tool, a->at, a->palm, a->q, a->arm, 0.5);
      const Side s = a == &r ? Side::right : Side::left;
      world->command_arm_rt(s, a->arm);
      world->command_hand_rt(s, a->q, a->k);
    }
    world->step_rt();
  }
  void hold(double s) {
    for (int i = 0, n = static_cast<int>(std::lround(s / params.dt_s)); i < n; ++i) step();
  }
  [[nodiscard]] const WorldHand& hand(Side s) const {
    return world->state().hand[static_cast<int>(s)];
  }
};

inline Vec3 pad(const WorldHand& h, int tip) {
  const float* p = h.tip[tip].position_mm;
  return {p[0], p[1], p[2]};
}

// B's arm A's tool along a straight line to TO, MM_PER_STEP each 1 ms step.
inline void move(Bimanual& b, Arm& a, Vec3 to, double mm_per_step) {
  const Vec3 from = a.at;
  const int n = std::max(1, static_cast<int>(std::lround(sheet::norm(to - from) / mm_per_step)));
  for (int i = 1; i <= n; ++i) {
    a.at = from + (to - from) * (static_cast<double>(i) / n);
    b.step();
  }
}

}  // namespace scene
