#include "core/assert.h"

#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

TEST_CASE("require_input throws ConfigError with the message") {
  CHECK_NOTHROW(crease::require_input(true, "fine"));
  try {
    crease::require_input(false, "sim.yaml:3:1: loops: at least one loop");
    FAIL("no throw");
  } catch (const crease::ConfigError& e) {
    CHECK(std::string(e.what()) == "sim.yaml:3:1: loops: at least one loop");
  }
}

TEST_CASE("CREASE_DEMAND aborts with the place and the reason") {
  int fds[2];
  REQUIRE(pipe(fds) == 0);
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    dup2(fds[1], 2);
    CREASE_DEMAND(1 + 1 == 3, "arithmetic is broken");
    _exit(0);
  }
  close(fds[1]);
  char buf[512] = {};
  const auto n = read(fds[0], buf, sizeof(buf) - 1);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGABRT);
  REQUIRE(n > 0);
  const std::string text(buf);
  CHECK(text.find("internal error at") != std::string::npos);
  CHECK(text.find("arithmetic is broken (1 + 1 == 3)") != std::string::npos);
}

TEST_CASE("require_input with a place throws the structured ConfigError") {
  CHECK_NOTHROW(crease::require_input(true, crease::SourceLoc{"sim.yaml", 3, 1}, "loops", "fine"));
  try {
    crease::require_input(false, crease::SourceLoc{"sim.yaml", 3, 1}, "loops", "at least one loop");
    FAIL("no throw");
  } catch (const crease::ConfigError& e) {
    CHECK(std::string(e.what()) == "sim.yaml:3:1: loops: at least one loop");
    CHECK(e.loc().line == 3);
    CHECK(e.key_path() == "loops");
    CHECK(e.reason() == "at least one loop");
  }
}
