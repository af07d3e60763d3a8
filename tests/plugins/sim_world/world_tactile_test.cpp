// The world's tactile sensors (world_tactile.h) without the drivers: the left hand's PST
// pressures go to its device, the right hand's taxels follow its fingertips' forces, the pty
// link is a symlink made at configure and removed after, a live link another robot holds is
// refused and a dangling one a dead robot left is replaced.
#include "plugins/sim_world/world_tactile.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "plugins/robot_model/robot_model.h"

using namespace crease;
namespace fs = std::filesystem;

namespace {
const robot::RobotModel& model() {
  static const robot::RobotModel m = robot::RobotModel::load(CREASE_SOURCE_DIR "/config/robot/crease_robot.yaml");
  return m;
}
std::string temp_link(const char* tag) { return (fs::temp_directory_path() / ("crease-t-wt-" + std::to_string(::getpid()) + tag)).string(); }
}  // namespace

TEST_CASE("world tactile: the index's force reaches the right hand's taxels and the left hand's PST") {
  drivers::sim::SimRobotConfig rc;
  rc.prefix = "crease-t-wt-" + std::to_string(::getpid());
  drivers::sim::SimRobot robot(rc);
  world::WorldTactile t(model().params(), 7, "");
  auto s = std::make_unique<WorldState>();
  for (int side = 0; side < 2; ++side) {
    s->hand[side].tip[0].contact = 1;
    s->hand[side].tip[0].normal_force_n = 1.0f;
  }
  for (int i = 0; i < 100; ++i) t.step_rt(*s, 0.001, robot, 1'000'000'000 + i * 1'000'000);
  const auto& pst = model().params().side(robot::Side::left).tactile.pst;
  // 10 kPa per N, less what the 30 s high-pass took in 0.1 s.
  CHECK(t.pst()[0] == doctest::Approx(pst.kpa_per_n * 1.0).epsilon(0.01));
  CHECK(t.pst()[1] < 0.05);
  double index = 0, others = 0;
  for (int k = 0; k < world::TactileModel::kTaxels; ++k) {
    index += t.taxels()[0][k];
    for (int f = 1; f < 5; ++f) others += t.taxels()[f][k];
  }
  const double area = model().params().side(robot::Side::right).tactile.taxel.taxel_area_mm2;
  CHECK(index * area / 1000.0 == doctest::Approx(1.0).epsilon(0.3));
  CHECK(others == 0.0);
  // Failing variant: no contact, no reading (the noise floor is under the threshold).
  s->hand[0].tip[0].contact = 0;
  s->hand[1].tip[0].contact = 0;
  t.step_rt(*s, 0.001, robot, 1'200'000'000);
  index = 0;
  for (int k = 0; k < world::TactileModel::kTaxels; ++k) index += t.taxels()[0][k];
  CHECK(index == 0.0);
  CHECK(t.pst()[0] < 0.05);
}

TEST_CASE("world tactile: the pty's link is made, refused when another holds it, replaced when dangling, removed") {
  const std::string link = temp_link("-tactile_r");
  fs::remove(link);
  {
    world::WorldTactile t(model().params(), 1, link);
    REQUIRE(fs::is_symlink(link));
    CHECK(fs::read_symlink(link).string().rfind("/dev/pts/", 0) == 0);
    CHECK(t.device() != nullptr);
    CHECK_THROWS_WITH_AS(world::WorldTactile(model().params(), 1, link), doctest::Contains("is taken"), std::runtime_error);
  }
  CHECK_FALSE(fs::exists(fs::symlink_status(link)));
  fs::create_symlink("/dev/pts/no-such-pty", link);  // a dead robot's
  {
    world::WorldTactile t(model().params(), 1, link);
    CHECK(fs::exists(link));
  }
  CHECK_FALSE(fs::exists(fs::symlink_status(link)));
}
