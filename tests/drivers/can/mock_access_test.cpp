// Access to a mock CAN bus (drivers/can/mock_access.h): another local user can neither read
// nor write a bus, a configured group admits its members, and a node does not join a broker
// that another user set up under the bus's name. The two-user cases create a system user
// (and group) and run crease-simdevice as that user through setpriv; they need root and print
// "SKIPPED: <reason>" (ctest reports them as skipped) where they cannot run.
#include "drivers/can/mock_access.h"

#include <doctest/doctest.h>
#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <pwd.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/can/candump_log.h"
#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"

extern char** environ;
using namespace crease::drivers;

namespace {
constexpr const char* kUser = "crease-bus-other";
constexpr const char* kGroup = "crease-bus-peers";

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Creates the system user and group once (idempotent). Empty string on success, else why not.
std::string ensure_other_user() {
  if (::geteuid() != 0) return "needs root to create a second user";
  if (!::getgrnam(kGroup) && std::system((std::string("groupadd --system ") + kGroup + " 2>/dev/null").c_str()) != 0 &&
      !::getgrnam(kGroup)) {
    return "groupadd failed";
  }
  if (!::getpwnam(kUser) &&
      std::system((std::string("useradd --system --no-create-home --shell /usr/sbin/nologin ") + kUser + " 2>/dev/null").c_str()) != 0 &&
      !::getpwnam(kUser)) {
    return "useradd failed";
  }
  if (::access("/usr/bin/setpriv", X_OK) != 0) return "no /usr/bin/setpriv";
  return "";
}

// A crease-simdevice process run as the other user; `groups` empty: none (setpriv --clear-groups).
struct OtherUserProcess {
  pid_t pid = -1;
  std::string out, err;
  OtherUserProcess(const std::vector<std::string>& args, const std::string& groups, const std::string& tag) {
    const passwd* pw = ::getpwnam(kUser);
    REQUIRE(pw != nullptr);
    const std::string base = "/tmp/crease_access_" + std::to_string(::getpid()) + "_" + tag;
    out = base + ".out";
    err = base + ".err";
    std::vector<std::string> argv = {"/usr/bin/setpriv", "--reuid=" + std::to_string(pw->pw_uid),
                                     "--regid=" + std::to_string(pw->pw_gid),
                                     groups.empty() ? std::string("--clear-groups") : "--groups=" + groups,
                                     std::string(CREASE_BIN_DIR) + "/crease-simdevice"};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<char*> cargv;
    for (auto& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    REQUIRE(posix_spawn(&pid, cargv[0], &fa, nullptr, cargv.data(), environ) == 0);
    posix_spawn_file_actions_destroy(&fa);
  }
  int wait() {
    int st = 0;
    REQUIRE(::waitpid(pid, &st, 0) == pid);
    pid = -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  }
  ~OtherUserProcess() {
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
    std::remove(out.c_str());
    std::remove(err.c_str());
  }
};

// Sends `marker` from `from` and reads `at` until it arrives; returns the frames before it.
int frames_before_marker(MockCanBus& from, MockCanBus& at, std::uint32_t marker) {
  REQUIRE(from.send(CanFrame::classic(marker, {})) == SendResult::ok);
  int before = 0;
  RxFrame rx;
  for (;;) {
    const RecvResult r = at.try_receive(rx);
    if (r == RecvResult::frame) {
      if (rx.frame.id() == marker) return before;
      ++before;
    } else {
      pollfd p{at.fd(), POLLIN, 0};
      REQUIRE(::poll(&p, 1, 10'000) == 1);
    }
  }
}

void wait_nodes(const MockCanBroker& b, int n) {
  for (int i = 0; i < 5000 && b.connected_nodes() < n; ++i) ::usleep(2000);
  REQUIRE(b.connected_nodes() == n);
}
}  // namespace

TEST_CASE("the owner's processes join its bus; nothing is refused") {
  const std::string name = "acc0-" + std::to_string(::getpid());
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a({name, 1, 0, 0}), b({name, 2, 0, 0});
  wait_nodes(broker, 2);
  CHECK(frames_before_marker(a, b, 0x7F0) == 0);
  CHECK(broker.stats().refused == 0);
}

TEST_CASE("an unknown group is an error naming it, for a broker and for a node") {
  CHECK_THROWS_WITH_AS(mockwire::make_bus_access("no-such-crease-group"),
                       doctest::Contains("no-such-crease-group"), std::invalid_argument);
  MockCanBrokerConfig cfg{"acc1-" + std::to_string(::getpid()), 0, 0, false, "no-such-crease-group"};
  CHECK_THROWS_AS(MockCanBroker{cfg}, std::invalid_argument);
}

TEST_CASE("another user can neither read nor write a bus; its refusals are counted") {
  if (const std::string why = ensure_other_user(); !why.empty()) {
    MESSAGE("SKIPPED: " << why);
    return;
  }
  const std::string name = "acc2-" + std::to_string(::getpid());
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus host({name, 1, 0, 0}), dev({name, 2, 0, 0});
  wait_nodes(broker, 2);

  // Read: `record` as the other user (it would log every frame of the bus).
  const std::string log = "/tmp/crease_access_" + std::to_string(::getpid()) + ".log";
  std::remove(log.c_str());
  {
    OtherUserProcess rec({"record", "--bus", name, "--out", log, "--seconds", "30"}, "", "rec");
    // The broker refuses it at once; while it would run, the bus is busy.
    for (int i = 0; i < 200; ++i) (void)host.send(CanFrame::classic(0x181, {}));
    CHECK(rec.wait() == 1);
    const std::string err = slurp(rec.err);
    INFO("record as " << std::string(kUser) << ": " << err);
    CHECK(err.find("refuses this user") != std::string::npos);
    CHECK(::access(log.c_str(), F_OK) != 0);  // nothing recorded, not even a file
  }
  CHECK(broker.stats().refused == 1);
  CHECK(broker.connected_nodes() == 2);
  CHECK(frames_before_marker(host, dev, 0x7F0) == 200);  // the device got the host's frames

  // Write: `replay` of an NMT "stop all" as the other user.
  const std::string in = "/tmp/crease_access_nmt_" + std::to_string(::getpid()) + ".log";
  {
    CandumpWriter w(in);
    CandumpEntry e;
    std::snprintf(e.interface, sizeof(e.interface), "can0");
    const std::uint8_t stop_all[2] = {0x02, 0x00};
    e.frame = CanFrame::classic(0x000, stop_all);
    for (int i = 0; i < 5; ++i) w.write(e);
  }
  ::chmod(in.c_str(), 0644);
  {
    OtherUserProcess rep({"replay", "--bus", name, "--in", in, "--speed", "0"}, "", "rep");
    CHECK(rep.wait() == 1);
    INFO("replay as " << std::string(kUser) << ": " << slurp(rep.err));
    CHECK(slurp(rep.err).find("refuses this user") != std::string::npos);
  }
  CHECK(broker.stats().refused == 2);
  CHECK(frames_before_marker(host, dev, 0x7F1) == 0);  // no NMT frame reached the device
  std::remove(in.c_str());
}

TEST_CASE("members of the bus's group are admitted (the check above refuses the user, not the tool)") {
  if (const std::string why = ensure_other_user(); !why.empty()) {
    MESSAGE("SKIPPED: " << why);
    return;
  }
  const group* g = ::getgrnam(kGroup);
  REQUIRE(g != nullptr);
  const std::string name = "acc3-" + std::to_string(::getpid());
  MockCanBroker broker({name, 0, 0, false, kGroup});
  MockCanBus host({name, 1, 0, 0});
  wait_nodes(broker, 1);
  const std::string log = "/tmp/crease_access_grp_" + std::to_string(::getpid()) + ".log";
  std::remove(log.c_str());
  {
    OtherUserProcess rec({"record", "--bus", name, "--out", log}, std::to_string(g->gr_gid), "grp");
    wait_nodes(broker, 2);
    for (int i = 0; i < 100; ++i) REQUIRE(host.send(CanFrame::classic(0x100 + static_cast<std::uint32_t>(i), {})) == SendResult::ok);
    // Delivered into the recorder's ring: then a SIGTERM makes it write them and exit.
    for (int i = 0; i < 5000 && broker.stats().forwarded < 100; ++i) ::usleep(2000);
    REQUIRE(broker.stats().forwarded == 100);
    ::kill(rec.pid, SIGTERM);
    CHECK(rec.wait() == 0);
    INFO("record as a member of " << std::string(kGroup) << ": " << slurp(rec.err));
  }
  CandumpReader r(log);
  CandumpEntry e;
  int lines = 0;
  while (r.next(e)) {
    CHECK(e.frame.id() == 0x100u + static_cast<std::uint32_t>(lines));
    ++lines;
  }
  CHECK(lines == 100);
  CHECK(broker.stats().refused == 0);
  std::remove(log.c_str());
}

TEST_CASE("a node does not join a broker another user runs under the bus's name") {
  if (const std::string why = ensure_other_user(); !why.empty()) {
    MESSAGE("SKIPPED: " << why);
    return;
  }
  const std::string name = "acc4-" + std::to_string(::getpid());
  OtherUserProcess impostor({"broker", "--bus", name, "--seconds", "60"}, "", "imp");
  for (int i = 0; i < 5000 && slurp(impostor.out).find("broker:") == std::string::npos; ++i) ::usleep(2000);
  REQUIRE(slurp(impostor.out).find("broker:") != std::string::npos);
  CHECK_THROWS_WITH_AS(MockCanBus({name, 1, 0, 0}), doctest::Contains("not joining a broker of another user"),
                       std::runtime_error);
}
