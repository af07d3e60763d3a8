// External substep contacts (substep_contacts.h) as XpbdSheet runs them: once per substep with
// its index and length, after the links and before the sheet's own contacts, and with the
// frame's candidates widened by the push they announce. Also plasticity_every.
#include "plugins/sheet_model/substep_contacts.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <vector>

#include "plugins/sheet_model/collision_world.h"
#include "plugins/sheet_model/xpbd_sheet.h"

using namespace crease::sheet;

namespace {

// Records its calls; optionally holds node 0 at a point, or moves every node down on the last
// substep.
class Recorder final : public SubstepContacts {
 public:
  void solve_rt(std::span<Vec3> x, std::span<const Vec3> prev, std::span<const double> w, int substep, int substeps,
                double dt_s) noexcept override {
    calls.push_back({substep, substeps, dt_s, x.size(), prev.size(), w.size()});
    if (hold) x[0] = held;
    if (drop_mm > 0 && substep == substeps - 1)
      for (Vec3& p : x) p.z -= drop_mm;
  }
  double max_push_mm(double) const noexcept override { return announced_mm; }

  struct Call {
    int substep, substeps;
    double dt_s;
    std::size_t nx, nprev, nw;
  };
  std::vector<Call> calls;
  bool hold = false;
  Vec3 held;
  double drop_mm = 0, announced_mm = 0;
};

SheetParams small() {
  SheetParams p;
  p.grid.nodes_u = 6;
  p.grid.nodes_v = 8;
  p.solver.substeps = 3;
  return p;
}

}  // namespace

TEST_CASE("the sheet calls its substep contacts once per substep, with the substep's index and length") {
  XpbdSheet s(small());
  Recorder r;
  s.set_substep_contacts(&r);
  s.step_rt(0.003);
  s.step_rt(0.003);
  REQUIRE(r.calls.size() == 6);
  for (int k = 0; k < 6; ++k) {
    CHECK(r.calls[k].substep == k % 3);
    CHECK(r.calls[k].substeps == 3);
    CHECK(r.calls[k].dt_s == doctest::Approx(0.001));
    CHECK(r.calls[k].nx == static_cast<std::size_t>(s.node_count()));
    CHECK(r.calls[k].nprev == r.calls[k].nx);
    CHECK(r.calls[k].nw == r.calls[k].nx);
  }
  s.set_substep_contacts(nullptr);
  s.step_rt(0.003);
  CHECK(r.calls.size() == 6);
}

TEST_CASE("what the substep contacts do stays: a node held against gravity, the rest falls") {
  XpbdSheet s(small());
  Recorder r;
  r.hold = true;
  r.held = s.positions()[0];
  s.set_substep_contacts(&r);
  for (int f = 0; f < 30; ++f) s.step_rt(1.0 / 60);
  CHECK(s.positions()[0].z == doctest::Approx(r.held.z).epsilon(1e-3));
  CHECK(s.positions()[s.node_count() - 1].z < r.held.z - 50.0);  // the far corner swung down
}

TEST_CASE("the sheet's own table contact acts after the substep contacts, on the nodes they may push") {
  // A flat sheet 10 mm above the table, no gravity; the substep contacts push every node 15 mm
  // down in the last substep. Candidates announced: the table catches the sheet at half its
  // thickness; not announced, the table's candidates miss the sheet and it ends below.
  for (const bool announce : {true, false}) {
    SheetParams p = small();
    p.solver.gravity_mm_per_s2 = {0, 0, 0};
    p.grid.origin_mm.z = 10.0;
    p.solver.max_speed_mm_per_s = 1e6;  // the push is one substep's
    XpbdSheet s(p);
    CollisionWorld table;
    table.add_table(0.0);
    s.set_collision_world(&table);
    Recorder r;
    r.drop_mm = 15.0;
    r.announced_mm = announce ? 16.0 : 0.0;
    s.set_substep_contacts(&r);
    s.step_rt(1.0 / 60);
    const double lowest = std::min_element(s.positions().begin(), s.positions().end(),
                                           [](const Vec3& a, const Vec3& b) { return a.z < b.z; })
                              ->z;
    if (announce) {
      CHECK(lowest == doctest::Approx(0.5 * p.grid.thickness_mm));
    } else {
      CHECK(lowest < 0.0);
    }
  }
}

TEST_CASE(
    "plasticity_every: each link's plastic update every that many substeps, a third of them after "
    "each") {
  SheetParams p = small();
  p.solver.substeps = 2;
  p.solver.plasticity_rate = 0.3;
  p.solver.yield_strain = 0.001;
  p.solver.plastic_bending_only = false;  // every link is plastic, in link order
  p.solver.plasticity_every = 3;
  p.solver.gravity_mm_per_s2 = {0, 0, 0};
  XpbdSheet s(p);
  // Two corners pinned far apart stretch the sheet beyond its yield strain.
  const Vec3 a = s.positions()[0], b = s.positions()[s.node_count() - 1];
  s.pin(0, a + Vec3{-30, 30, 0});
  s.pin(s.node_count() - 1, b + Vec3{30, -30, 0});
  // Links are dealt out in blocks of 8: link k is updated after the substeps whose count, from
  // 0, is k / 8 mod 3 (mod 3).
  auto plastic_in_turn = [&](int turn) {
    const auto e = s.plastic_elongations();
    bool any = false;
    for (std::size_t k = 0; k < e.size(); ++k)
      any = any || (static_cast<int>(k / 8 % 3) == turn && e[k] != 0.0);
    return any;
  };
  s.step_rt(0.01);  // substeps 0, 1: the links of turns 0 and 1
  CHECK(plastic_in_turn(0));
  CHECK(plastic_in_turn(1));
  CHECK_FALSE(plastic_in_turn(2));
  s.step_rt(0.01);  // substeps 2, 3: turn 2 (counted across frames), then turn 0 again
  CHECK(plastic_in_turn(2));
}
