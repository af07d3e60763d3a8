// Pressing a fingertip onto the sheet on the table: the contact force grows with the depth the
// arm drives the fingertip's target below the sheet, and the finger's joints deviate from
// their targets monotonically with that force (the compliant joints of seed 000 Eq. 5).
// Failing variants: without the hands' contacts no force builds; with rigid joints none deviates.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "scene.h"

using namespace scene;

namespace {

struct Sample {
  double depth_mm;         // of the fingertip's target below the first contact
  double force_n;          // the index fingertip's normal force
  double mcp_rad, wrist_rad;  // |deviation| of FFJ3 and WRJ1
  double penetration_mm;
};

// The right index descends at 10 mm/s onto the sheet's centre; from the first contact it is
// pressed in 2 mm steps, each held 0.2 s.
std::vector<Sample> press(WorldParams p) {
  p.initial_stiffness_nm_per_rad = 2.0;
  const Vec3 above{0, 0, 8};
  Rig rig(p, "ffpad", above, palm_forward_down(robot::Side::right, deg(30)), index_out());
  const WorldState& s = rig.world->state();
  const double z_contact = rig.descend_to_contact(0, 10.0, -2.0);
  std::vector<Sample> out;
  for (double depth = 2; depth <= 12; depth += 2) {
    rig.move({0, 0, z_contact - depth}, 10.0, 0.2);
    const WorldHand& h = s.hand[0];
    out.push_back({depth, h.tip[0].normal_force_n, std::fabs(h.deflection_rad[FFJ3]), std::fabs(h.deflection_rad[WRJ1]),
                   rig.world->max_penetration_mm()});
  }
  return out;
}

bool force_grows_with_depth(const std::vector<Sample>& v) {
  bool ok = v.front().force_n > 0.05;
  for (std::size_t i = 1; i < v.size(); ++i) ok = ok && v[i].force_n > v[i - 1].force_n + 0.01;
  return ok;
}

bool joints_follow_force(const std::vector<Sample>& v) {
  bool ok = true;
  for (std::size_t i = 1; i < v.size(); ++i) {
    ok = ok && v[i].force_n > v[i - 1].force_n;
    ok = ok && v[i].mcp_rad > v[i - 1].mcp_rad + 1e-4 && v[i].wrist_rad > v[i - 1].wrist_rad + 1e-4;
  }
  return ok;
}

void print(const char* tag, const std::vector<Sample>& v) {
  for (const Sample& s : v) {
    MESSAGE(std::string(tag) << ": depth " << s.depth_mm << " mm: force " << s.force_n << " N, FFJ3 " << s.mcp_rad
                << " rad, WRJ1 " << s.wrist_rad << " rad, worst depth in the sheet " << s.penetration_mm << " mm");
  }
}

}  // namespace

TEST_CASE("a fingertip pressed onto the sheet: the force grows with the depth, the joints deviate with the force") {
  const std::vector<Sample> on = press(nominal());
  print("press", on);
  CHECK(force_grows_with_depth(on));
  CHECK(joints_follow_force(on));
  // Figure: the fingertip's stiffness over the presses (N/mm): the hand's joints in series with
  // the cover, at 2 N m/rad.
  const double k = (on.back().force_n - on.front().force_n) / (on.back().depth_mm - on.front().depth_mm);
  MESSAGE("fingertip stiffness " << k << " N/mm at 2 N m/rad");
  CHECK(k > 0.02);
  for (const Sample& s : on) CHECK(s.penetration_mm < 1.0);

  WorldParams no_contacts = nominal();
  no_contacts.hand_contacts = false;
  const std::vector<Sample> off = press(no_contacts);
  CHECK_FALSE(force_grows_with_depth(off));

  WorldParams rigid = nominal();
  rigid.joint_compliance = false;
  const std::vector<Sample> stiff = press(rigid);
  print("rigid joints", stiff);
  CHECK_FALSE(joints_follow_force(stiff));
}
