// The hand's quasi-static balance on the shipped right hand with contacts written inline: the
// spring torques balance J^T f, a limp hand yields until nothing presses, a gap closes when the
// hand is pushed into it, springs saturate at the joints' efforts and joints stop at their
// limits, rigid joints do not move, and nothing allocates.
#include "plugins/sim_world/hand_compliance.h"

#include <doctest/doctest.h>

#include <array>
#include <algorithm>
#include <cmath>
#include <vector>

#include "rt/alloc_guard.h"
#include "scene.h"

using namespace scene;

namespace {

struct Setup {
  Setup() : kin(robot_model(), robot::Side::right) {
    const auto& hj = robot_model().hand_joints(robot::Side::right);
    for (int j = 0; j < robot::kHandJoints; ++j) {
      lim.lower_rad[j] = hj[j].lower_rad;
      lim.upper_rad[j] = hj[j].upper_rad;
      lim.effort_nm[j] = hj[j].effort_nm;
    }
    hc.configure(lim);
    target = index_out();
    target[FFJ3] = 0.3;
    target[FFJ2] = 0.3;
    kin.update_rt(ArmQ{}, target);
    pad = kin.link_index("r_ffpad");
    const Pose& p = kin.link_pose(pad);
    point = p.t;
    outward = p.axis(2);  // the pad's outward normal: a node there is pushed along it
  }
  // Joint torques of the contacts' forces on the hand (N mm).
  HandQ torque(std::span<const HandCompliance::Contact> cs, std::span<const double> f) const {
    HandQ t{};
    for (std::size_t c = 0; c < cs.size(); ++c)
      kin.add_hand_jacobian_transpose(cs[c].link, cs[c].point, -f[c] * cs[c].normal, t);
    return t;
  }
  SideKinematics kin;
  HandCompliance::Limits lim;
  HandCompliance hc;
  HandQ target{};
  int pad = -1;
  Vec3 point, outward;
};

}  // namespace

TEST_CASE("the joints settle where their springs balance J^T f of the contact") {
  Setup s;
  HandQ k{};
  k.fill(2.0);
  const std::array<HandCompliance::Contact, 1> cs{{{s.pad, s.point, s.outward, 0.5, 40.0}}};
  HandQ dq{}, none{};
  std::array<double, 1> f{};
  s.hc.solve_rt(s.kin, cs, s.target, k, none, true, dq, f);
  CHECK(f[0] > 0);
  CHECK(f[0] < 40.0 * 0.5);  // the finger gave way: less than the cover alone would push
  const HandQ t = s.torque(cs, f);
  // To 1e-4: the solve holds every joint with 0.01 N mm/rad more than its spring (5e-6 of it).
  for (int j = 0; j < robot::kHandJoints; ++j) CHECK(1000.0 * k[j] * dq[j] == doctest::Approx(t[j]).epsilon(1e-4).scale(1e-6));
  CHECK(std::fabs(dq[FFJ3]) > 1e-3);
  CHECK(s.hc.saturated() == 0);
  CHECK(s.hc.at_limit() == 0);
}

TEST_CASE("a limp hand yields until nothing presses; rigid joints do not move") {
  Setup s;
  const std::array<HandCompliance::Contact, 1> cs{{{s.pad, s.point, s.outward, 0.5, 40.0}}};
  HandQ limp{}, none{}, dq{};
  std::array<double, 1> f{};
  s.hc.solve_rt(s.kin, cs, s.target, limp, none, true, dq, f);
  CHECK(f[0] < 1e-6);
  HandQ stiff{};
  stiff.fill(2.0);
  HandQ dq2{};
  s.hc.solve_rt(s.kin, cs, s.target, stiff, none, false, dq2, f);
  for (double d : dq2) CHECK(d == 0.0);
  CHECK(f[0] == doctest::Approx(40.0 * 0.5));
}

TEST_CASE("a gap closes when the hand is pushed into it, and stays open otherwise") {
  Setup s;
  HandQ k{};
  k.fill(2.0);
  const std::array<HandCompliance::Contact, 1> cs{{{s.pad, s.point, s.outward, -0.5, 40.0}}};
  HandQ none{}, dq{};
  std::array<double, 1> f{};
  s.hc.solve_rt(s.kin, cs, s.target, k, none, true, dq, f);
  CHECK(f[0] == 0.0);
  for (double d : dq) CHECK(d == 0.0);
  // A torque flexing the index into the sheet: the pad closes the gap and the contact holds it.
  HandQ push{};
  s.kin.add_hand_jacobian_transpose(s.pad, s.point, 2.0 * s.outward, push);  // 2 N towards the node
  HandQ dq2{};
  s.hc.solve_rt(s.kin, cs, s.target, k, push, true, dq2, f);
  CHECK(f[0] > 0.5);
}

TEST_CASE("springs saturate at the joints' efforts; joints stop at their limits") {
  Setup s;
  HandQ k{};
  k.fill(300.0);  // stiff: the cover's compression would give tens of N
  const std::array<HandCompliance::Contact, 1> cs{{{s.pad, s.point, s.outward, 3.0, 200.0}}};
  HandQ none{}, dq{};
  std::array<double, 1> f{};
  s.hc.solve_rt(s.kin, cs, s.target, k, none, true, dq, f);
  CHECK(s.hc.saturated() > 0);
  // A saturated joint yields: its spring gives the effort, and the contact's torque is that.
  const HandQ tq = s.torque(cs, f);
  int yielded = 0;
  for (int j = 0; j < robot::kHandJoints; ++j) {
    if (300.0 * std::fabs(dq[j]) <= s.lim.effort_nm[j]) {
      CHECK(300e3 * dq[j] == doctest::Approx(tq[j]).epsilon(1e-4).scale(1e-6));
    } else {
      ++yielded;
      CHECK(std::fabs(tq[j]) == doctest::Approx(1000.0 * s.lim.effort_nm[j]).epsilon(1e-4));
    }
  }
  CHECK(yielded == s.hc.saturated());
  // The index's PIP at its lower limit, pushed further: it stays there.
  Setup t;
  t.target[FFJ2] = t.lim.lower_rad[FFJ2];
  t.kin.update_rt(ArmQ{}, t.target);
  const Pose& p = t.kin.link_pose(t.pad);
  const std::array<HandCompliance::Contact, 1> c2{{{t.pad, p.t, p.axis(2), 2.0, 40.0}}};
  HandQ soft{};
  soft.fill(0.5);
  HandQ d2{};
  t.hc.solve_rt(t.kin, c2, t.target, soft, none, true, d2, f);
  for (int j = 0; j < robot::kHandJoints; ++j) {
    CHECK(t.target[j] + d2[j] >= t.lim.lower_rad[j] - 1e-12);
    CHECK(t.target[j] + d2[j] <= t.lim.upper_rad[j] + 1e-12);
  }
  CHECK(t.hc.at_limit() > 0);
}

TEST_CASE("every contact configured for is solved; beyond the capacity none gets a force and the solve is counted") {
  // 1500 contacts (a hand over a fine sheet lists that many nodes and gaps), the only pressing
  // one last, as the table's contacts come after the sheet's.
  Setup s;
  HandQ k{};
  k.fill(2.0);
  std::vector<HandCompliance::Contact> cs(1500, HandCompliance::Contact{s.pad, s.point, s.outward, -2.0, 40.0});
  cs.back().depth_mm = 0.5;
  std::vector<double> f(cs.size(), -1.0);
  HandQ none{}, dq{};
  HandCompliance big;
  big.configure(s.lim, 1500);
  big.solve_rt(s.kin, cs, s.target, k, none, true, dq, f);
  CHECK(big.truncated() == 0);
  CHECK(f.back() > 1e-3);
  CHECK(std::fabs(dq[FFJ3]) > 1e-3);
  for (std::size_t c = 0; c + 1 < cs.size(); ++c) CHECK(f[c] == 0.0);
  // Room for 1024 (the old fixed size): the pressing one is not solved, gets no force (not a
  // stale one), the hand does not move for it, and the solve is counted.
  HandCompliance small;
  small.configure(s.lim, 1024);
  std::fill(f.begin(), f.end(), 7.0);
  HandQ dq2{};
  small.solve_rt(s.kin, cs, s.target, k, none, true, dq2, f);
  CHECK(small.truncated() == 1);
  CHECK(f.back() == 0.0);
  for (double d : dq2) CHECK(d == 0.0);
}

TEST_CASE("a joint a nanoradian inside the limit the contact pushes it to stops there; the others balance") {
  // As the force controller's ramp leaves a joint held at its limit since the last step. (In
  // the fold's slide such a joint, passed and clipped by the Newton step, turned the step
  // uphill and the balance stalled with the pad pressing 3-5 N: the solve now puts a joint that
  // near on its bound.)
  Setup s;
  HandQ g{};
  s.kin.add_hand_jacobian_transpose(s.pad, s.point, s.outward, g);  // the contact pushes the joints along -g
  REQUIRE(std::fabs(g[FFJ2]) > 1.0);
  const bool to_lower = g[FFJ2] > 0;
  const double limit = to_lower ? s.lim.lower_rad[FFJ2] : s.lim.upper_rad[FFJ2];
  HandQ dq{};
  dq[FFJ2] = (to_lower ? 1.0 : -1.0) * 1.2e-9;  // the angle limit + 1.2e-9 inside
  s.target[FFJ2] = limit;
  HandQ q = s.target;
  q[FFJ2] += dq[FFJ2];
  s.kin.update_rt(ArmQ{}, q);
  const Pose& p = s.kin.link_pose(s.pad);
  const std::array<HandCompliance::Contact, 1> cs{{{s.pad, p.t, p.axis(2), 1.0, 40.0}}};
  HandQ k{};
  k.fill(2.0);
  HandQ none{};
  std::array<double, 1> f{};
  s.hc.solve_rt(s.kin, cs, s.target, k, none, true, dq, f);
  CHECK(f[0] < 0.5 * 40.0 * 1.0);  // the finger gave way
  CHECK(s.hc.at_limit() >= 1);
  CHECK(std::fabs(s.target[FFJ2] + dq[FFJ2] - limit) < 1e-9);
  // The springs balance the contact's torque on every joint off its limit.
  const HandQ t = s.torque(cs, f);
  for (int j = 0; j < robot::kHandJoints; ++j)
    if (j != FFJ2) CHECK(1000.0 * k[j] * dq[j] == doctest::Approx(t[j]).epsilon(1e-4).scale(1e-3));
}

TEST_CASE("with a step bound the deflection moves at most that far per solve, and gets there over solves") {
  Setup s;
  HandQ k{};
  k.fill(0.2);  // soft: the finger yields far
  HandQ none{}, dq{};
  std::array<double, 1> f{};
  HandCompliance::Joints unbounded{};
  {
    const std::array<HandCompliance::Contact, 1> cs{{{s.pad, s.point, s.outward, 12.0, 40.0}}};
    s.hc.solve_rt(s.kin, cs, s.target, k, none, true, unbounded, f);
  }
  double far = 0;
  for (double d : unbounded) far = std::max(far, std::fabs(d));
  REQUIRE(far > 0.04);
  HandCompliance bounded;
  bounded.configure(s.lim, 4);
  bounded.set_max_step_rad(0.005);
  // The contact as the world measures it each step: its depth where the last deflection left it.
  for (int step = 0; step < 200; ++step) {
    HandQ g{};
    const HandQ before = dq;
    // Depth linear in the deflection about the undeflected pose (as the unbounded solve saw it).
    double depth = 12.0;
    s.kin.add_hand_jacobian_transpose(s.pad, s.point, s.outward, g);
    for (int j = 0; j < robot::kHandJoints; ++j) depth += g[j] * dq[j];
    const std::array<HandCompliance::Contact, 1> cs{{{s.pad, s.point, s.outward, depth, 40.0}}};
    bounded.solve_rt(s.kin, cs, s.target, k, none, true, dq, f);
    for (int j = 0; j < robot::kHandJoints; ++j) CHECK(std::fabs(dq[j] - before[j]) <= 0.005 + 1e-12);
  }
  for (int j = 0; j < robot::kHandJoints; ++j) CHECK(dq[j] == doctest::Approx(unbounded[j]).epsilon(1e-3).scale(1e-4));
}

TEST_CASE("solve_rt allocates nothing") {
  REQUIRE(crease::rt::alloc_hooks_installed());
  Setup s;
  HandQ k{};
  k.fill(2.0);
  const std::array<HandCompliance::Contact, 1> cs{{{s.pad, s.point, s.outward, 0.5, 40.0}}};
  HandQ none{}, dq{};
  std::array<double, 1> f{};
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark rt;
    for (int i = 0; i < 200; ++i) s.hc.solve_rt(s.kin, cs, s.target, k, none, true, dq, f);
  }
  CHECK(crease::rt::rt_allocation_count() == before);
}
