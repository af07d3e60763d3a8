// The world's tactile sensors (world_tactile.h) without the drivers: the left hand's PST
// pressures go to its device, the right hand's taxels follow its fingertips' forces, the link
// is a Unix socket made at configure and removed after, a live link another robot holds is
// refused and a dead one a dead robot left is replaced; the samples reach a connected host, and
// the next connection once it hangs up.
#include "plugins/sim_world/world_tactile.h"

#include <doctest/doctest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

#include "drivers/protocol/tactile_protocol.h"
#include "drivers/serial/unix_link.h"
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

TEST_CASE("world tactile: the link is a socket made at configure, refused when another holds it, replaced when dead, removed") {
  const std::string link = temp_link("-tactile_r");
  fs::remove(link);
  {
    world::WorldTactile t(model().params(), 1, link);
    REQUIRE(drivers::is_unix_socket(link));
    CHECK(t.device() != nullptr);
    CHECK_THROWS_WITH_AS(world::WorldTactile(model().params(), 1, link), doctest::Contains("is taken"), std::runtime_error);
  }
  CHECK_FALSE(fs::exists(fs::symlink_status(link)));
  fs::create_symlink("/dev/pts/no-such-pty", link);  // a dead robot's pty link
  {
    world::WorldTactile t(model().params(), 1, link);
    CHECK(drivers::is_unix_socket(link));
  }
  CHECK_FALSE(fs::exists(fs::symlink_status(link)));
  {
    // A socket nobody listens on (a robot killed before it removed its link) is replaced.
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strncpy(a.sun_path, link.c_str(), sizeof a.sun_path - 1);
    REQUIRE(::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0);
    ::close(fd);
    REQUIRE(drivers::is_unix_socket(link));
    world::WorldTactile t(model().params(), 1, link);
    CHECK_NOTHROW((void)drivers::connect_unix_link(link));
  }
  CHECK_FALSE(fs::exists(fs::symlink_status(link)));
}

namespace {
// The host's end of the link, as hand_driver's reader uses it: sends Start, counts samples.
struct Host {
  int fd;
  drivers::SerialDeframer deframer;
  explicit Host(const std::string& link) : fd(drivers::connect_unix_link(link)) {
    std::uint8_t p[2], wire[drivers::kSerialMaxWire];
    const std::size_t n = drivers::tactile::encode_start(250, p);
    const std::size_t w = drivers::serial_encode(0, drivers::tactile::kTypeStart, {p, n}, wire);
    REQUIRE(::write(fd, wire, w) == static_cast<long>(w));
  }
  ~Host() {
    if (fd >= 0) ::close(fd);
  }
  int samples() {
    int got = 0;
    std::uint8_t buf[4096];
    for (long n; (n = ::read(fd, buf, sizeof buf)) > 0;) {
      for (std::size_t pos = 0; pos < static_cast<std::size_t>(n);) {
        drivers::SerialFrame f;
        bool ok = false;
        pos += deframer.feed({buf + pos, static_cast<std::size_t>(n) - pos}, f, &ok);
        drivers::tactile::Sample s;
        if (ok && drivers::tactile::decode_sample(f, s) == drivers::Decode::ok) ++got;
      }
    }
    return got;
  }
};
}  // namespace

// Served over the socket at the rate the host asks (250 Hz: a sample every 4 world steps); a
// second connection (a hot-swapped driver's) waits, and takes over once the first hangs up.
TEST_CASE("world tactile: the samples reach the connected host; the next connection takes over when it hangs up") {
  const std::string link = temp_link("-tactile_s");
  fs::remove(link);
  drivers::sim::SimRobotConfig rc;
  rc.prefix = "crease-t-ws-" + std::to_string(::getpid());
  drivers::sim::SimRobot robot(rc);
  world::WorldTactile t(model().params(), 1, link);
  auto s = std::make_unique<WorldState>();
  std::int64_t ns = 1'000'000'000;
  const auto steps = [&](int n) {
    for (int i = 0; i < n; ++i) t.step_rt(*s, 0.001, robot, ns += 1'000'000);
  };
  steps(10);
  CHECK(t.connections() == 0);
  CHECK(t.device()->samples_sent() == 0);  // nobody connected: nothing sent, nothing dropped
  CHECK(t.device()->samples_dropped() == 0);
  auto first = std::make_unique<Host>(link);
  steps(200);
  CHECK(t.connections() == 1);
  const int got = first->samples();
  CHECK(got >= 45);  // 200 steps at one sample in 4, from its Start on
  CHECK(got <= 51);
  Host second(link);
  steps(100);
  CHECK(second.samples() == 0);  // waiting behind the first
  CHECK(first->samples() >= 20);
  first.reset();  // the old driver goes
  steps(100);
  CHECK(t.connections() == 2);
  CHECK(second.samples() >= 15);
  // What it sent the first before it saw it gone (it looks every 8 steps: at most 2 samples)
  // is dropped and counted, with no SIGPIPE.
  CHECK(t.device()->samples_dropped() <= 2);
}
