// The world's step as a unit: one seed, one trajectory (bit for bit); bad commands clamped,
// refused and counted; a non-finite step rolled back; the fastest motions the drives allow
// never put a finger more than 1 mm into the sheet or the table; a step allocates nothing; the
// sheet exported as a SheetState; how deep the kinematic arms reach under the table; the sheet
// pushed into the table's slab comes back out through its top.
#include "plugins/sim_world/sim_world.h"

#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "rt/alloc_guard.h"
#include "scene.h"

using namespace scene;

namespace {

// The index presses the sheet and pulls it 10 mm; the sheet's positions at the end.
std::vector<Vec3> run(const WorldParams& p, WorldState* state = nullptr) {
  const Vec3 above{20, 40, 8};
  Rig rig(p, "ffpad", above, palm_forward_down(robot::Side::right, deg(30)), index_out());
  const double zc = rig.descend_to_contact(0, 20.0, -2.0);
  rig.move({above.x, above.y, zc - 6}, 20.0, 0.05);
  rig.move({above.x, above.y - 10, zc - 6}, 20.0);
  if (state != nullptr) *state = rig.world->state();
  return {rig.world->sheet().positions().begin(), rig.world->sheet().positions().end()};
}

}  // namespace

TEST_CASE("the same seed and the same commands give the same world, bit for bit; another seed another") {
  WorldParams p;  // randomised
  p.seed = 7;
  auto a_state = std::make_unique<WorldState>(), b_state = std::make_unique<WorldState>();
  const std::vector<Vec3> a = run(p, a_state.get()), b = run(p, b_state.get());
  REQUIRE(a.size() == b.size());
  CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0);
  CHECK(std::memcmp(&a_state->hand, &b_state->hand, sizeof(a_state->hand)) == 0);
  CHECK(a_state->hand[0].tip[0].contact == 1);
  WorldParams q = p;
  q.seed = 8;
  const std::vector<Vec3> c = run(q);
  CHECK(std::memcmp(a.data(), c.data(), a.size() * sizeof(Vec3)) != 0);
  const World w(robot_model(), p);
  MESSAGE(describe(p.seed, w.draws()));
}

TEST_CASE("targets beyond the URDF's limits are clamped, non-finite ones and bad stiffness refused, each counted") {
  World w(robot_model(), nominal());
  const auto& hj = robot_model().hand_joints(robot::Side::right);
  const auto& aj = robot_model().arm_joints(robot::Side::right);
  HandQ target = w.hand_targets(robot::Side::right), k{};
  k.fill(1.5);
  target[FFJ3] = 10.0;  // beyond its upper limit
  w.command_hand_rt(robot::Side::right, target, k);
  CHECK(w.state().clamped_targets == 1);
  for (int i = 0; i < 1000; ++i) w.step_rt();  // the drive gets there at its velocity limit
  CHECK(w.hand_targets(robot::Side::right)[FFJ3] == hj[FFJ3].upper_rad);
  CHECK(w.state().rate_limited > 0);
  CHECK(w.hand_stiffness(robot::Side::right)[FFJ3] == 1.5);

  target[FFJ2] = std::numeric_limits<double>::quiet_NaN();
  k[FFJ2] = -1.0;
  k[FFJ4] = std::numeric_limits<double>::infinity();
  k[MFJ3] = std::numeric_limits<double>::quiet_NaN();
  w.command_hand_rt(robot::Side::right, target, k);
  CHECK(w.state().refused_targets == 1);
  CHECK(w.state().refused_stiffness == 3);
  CHECK(w.state().clamped_targets == 2);  // FFJ3's 10 rad again
  w.step_rt();
  CHECK(std::isfinite(w.hand_targets(robot::Side::right)[FFJ2]));
  CHECK(w.hand_stiffness(robot::Side::right)[FFJ2] == 1.5);  // the last accepted
  CHECK(w.hand_stiffness(robot::Side::right)[FFJ4] == 1.5);
  CHECK(w.hand_stiffness(robot::Side::right)[MFJ3] == 1.5);

  ArmQ arm = w.arm_angles(robot::Side::right);
  arm[3] = -100.0;
  arm[5] = std::numeric_limits<double>::infinity();
  w.command_arm_rt(robot::Side::right, arm);
  CHECK(w.state().clamped_targets == 3);
  CHECK(w.state().refused_targets == 2);
  for (int i = 0; i < 2000; ++i) w.step_rt();
  CHECK(w.arm_angles(robot::Side::right)[3] == aj[3].lower_rad);
  CHECK(w.state().all_finite());
}

TEST_CASE("a step that goes non-finite is rolled back and counted, and the world goes on") {
  const Vec3 above{0, 0, 8};
  Rig rig(nominal(), "ffpad", above, palm_forward_down(robot::Side::right, deg(30)), index_out());
  const double zc = rig.descend_to_contact(0, 20.0, -2.0);
  rig.move({0, 0, zc - 4}, 20.0, 0.05);
  const std::vector<Vec3> before(rig.world->sheet().positions().begin(), rig.world->sheet().positions().end());
  const std::vector<double> plastic(rig.world->sheet().plastic_elongations().begin(),
                                    rig.world->sheet().plastic_elongations().end());
  rig.world->poison_next_step_for_test();
  rig.step_to(rig.last);
  CHECK(rig.world->state().rollbacks == 1);
  const auto after = rig.world->sheet().positions();
  CHECK(std::memcmp(before.data(), after.data(), before.size() * sizeof(Vec3)) == 0);
  CHECK(std::equal(plastic.begin(), plastic.end(), rig.world->sheet().plastic_elongations().begin()));
  rig.hold(0.05);
  CHECK(rig.world->state().rollbacks == 1);
  CHECK(rig.world->state().all_finite());
  CHECK(rig.hand().tip[0].contact == 1);
}

namespace {

// The worst depth (geometric) of any shape of the hand in the sheet or the table while the
// index flexes at its drive's fastest (2 rad/s, the URDF's limit) from 5 mm above the sheet
// into it, at the largest stiffness the hand protocol carries (655.35 N m/rad).
double flex_into(WorldParams p) {
  p.initial_stiffness_nm_per_rad = 655.35;
  Rig rig(p, "ffpad", {0, 0, 5.0}, palm_forward_down(robot::Side::right, deg(30)), index_out());
  rig.hand_q[FFJ3] = deg(40);  // commanded at once: the drive slews at its limit
  double worst = 0;
  for (int i = 0; i < 500; ++i) {
    rig.step_to(rig.last);
    worst = std::max(worst, rig.world->geometric_penetration_mm());
  }
  CHECK(rig.world->state().rate_limited > 100);
  return worst;
}

// The same while the arm drives the hand straight down at 1 m/s (the PA-10's joints at up to
// about a third of their 180 deg/s here) to 15 mm past the index's first contact.
double drive_into(WorldParams p) {
  p.initial_stiffness_nm_per_rad = 655.35;
  Rig rig(p, "ffpad", {0, 0, 30}, palm_forward_down(robot::Side::right, deg(30)), index_out());
  double worst = 0;
  for (double z = 30; z > -10; z -= 1.0) {
    rig.last.z = z;
    rig.step_to(rig.last);
    worst = std::max(worst, rig.world->geometric_penetration_mm());
  }
  rig.hold(0.1);
  return std::max(worst, rig.world->geometric_penetration_mm());
}

}  // namespace

TEST_CASE("at the fastest motions the drives allow a finger goes at most 1 mm (flexing) or 5 mm (driven by the arm) into the sheet or the table") {
  const double flex = flex_into(nominal()), drive = drive_into(nominal());
  MESSAGE("worst depth: index flexing at 2 rad/s " << flex << " mm, hand driven down at 1 m/s " << drive << " mm");
  CHECK(flex < 1.0);
  // Driven down at 1 m/s with its joints at their efforts (~30 N), the index's distal cover
  // lets a node of the sheet in front of the pad through (4.3 mm; 0 with the arms mounted at
  // 1.3 m, the same hand pose reached by another arm posture within 0.01 mm and 1e-4 rad).
  CHECK(drive < 5.0);
  WorldParams ghost = nominal();
  ghost.hand_contacts = false;
  const double flex0 = flex_into(ghost), drive0 = drive_into(ghost);
  MESSAGE("without the hands' contacts: " << flex0 << " mm, " << drive0 << " mm");
  CHECK_FALSE(flex0 < 1.0);
  CHECK_FALSE(drive0 < 5.0);
}

TEST_CASE("a world step with a hand pressing the sheet allocates nothing; the sheet exports as a SheetState") {
  REQUIRE(crease::rt::alloc_hooks_installed());
  const Vec3 above{0, 0, 8};
  Rig rig(nominal(), "ffpad", above, palm_forward_down(robot::Side::right, deg(30)), index_out());
  const double zc = rig.descend_to_contact(0, 20.0, -2.0);
  rig.move({0, 0, zc - 5}, 20.0, 0.05);
  auto sheet_state = std::make_unique<SheetState>();
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark mark;
    for (int i = 0; i < 200; ++i) {
      rig.world->command_arm_rt(robot::Side::right, rig.q);
      rig.world->command_hand_rt(robot::Side::right, rig.hand_q, rig.stiffness);
      rig.world->step_rt();
    }
    rig.world->export_sheet_rt(*sheet_state);
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  CHECK(rig.hand().tip[0].contact == 1);
  CHECK(sheet_state->nodes_u == 29);
  CHECK(sheet_state->nodes_v == 41);
  CHECK(sheet_state->all_finite());
  CHECK(sheet_state->step == rig.world->state().step);
  CHECK(sheet_state->timestamp_ns == rig.world->state().timestamp_ns);
  const auto x = rig.world->sheet().positions();
  CHECK(sheet_state->position_mm[600][2] == static_cast<float>(x[600].z));
  CHECK(sheet_state->normal[600][2] > 0.99f);  // flat on the table, printed face up
  CHECK(rig.world->state().sheet_table_contact_area_mm2 == doctest::Approx(210.0 * 297.0).epsilon(0.02));
}

TEST_CASE(
    "world_state reports per side how deep the kinematic arm and forearm reach under the table's "
    "top") {
  WorldState pressing;
  (void)run(nominal(), &pressing);  // the right index presses the sheet on the table
  MESSAGE("pressing: under the table right " << pressing.under_table_mm[0] << " mm, left "
                                             << pressing.under_table_mm[1]);
  CHECK(pressing.under_table_mm[0] == 0.0f);
  CHECK(pressing.under_table_mm[1] == 0.0f);
  CHECK(pressing.all_finite());
  // The same hand pose with the table 300 mm higher (the hand's contacts off, so that nothing
  // stops the fingers): the right wrist and forearm are under its top (and the parked left
  // arm partly: 300 mm is over its lowest link).
  WorldParams raised = nominal();
  raised.hand_contacts = false;
  raised.table_height_mm = 300.0;
  const Vec3 above{20, 40, 8};
  Rig rig(raised, "ffpad", above, palm_forward_down(robot::Side::right, deg(30)), index_out());
  rig.hold(0.05);
  const WorldState& s = rig.world->state();
  MESSAGE("table raised 300 mm: under the table right " << s.under_table_mm[0] << " mm, left "
                                                        << s.under_table_mm[1]);
  CHECK(s.under_table_mm[0] > 100.0f);
  CHECK(s.under_table_mm[0] < 400.0f);
  CHECK(s.all_finite());
}

TEST_CASE(
    "a patch of the sheet pushed into the table comes back out through its top, at any depth the "
    "slab holds") {
  for (const double depth : {1.0, 2.0, 3.0, 4.5, 8.0, 20.0}) {
    CAPTURE(depth);
    Rig rig(nominal(), "ffpad", {20, 40, 80}, palm_forward_down(robot::Side::right, deg(30)),
            index_out());
    auto& sheet = rig.world->sheet();
    std::vector<Vec3> x(sheet.positions().begin(), sheet.positions().end());
    const auto& g = sheet.grid();
    // A 5 x 5 patch in the middle of the sheet, DEPTH under the top (its edges slope down to it).
    for (int j = 18; j < 23; ++j)
      for (int i = 12; i < 17; ++i) x[g.index(i, j)].z = -depth;
    sheet.set_positions(x);
    rig.hold(0.3);
    double lowest = 1e9;
    for (const Vec3& p : rig.world->sheet().positions()) lowest = std::min(lowest, p.z);
    CHECK(lowest > -0.1);
    CHECK(lowest < 1.0);
  }
}
