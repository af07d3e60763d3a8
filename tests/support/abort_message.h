// For tests of the CREASE_DEMAND tier (core/assert.h): runs `fn` in a forked child and returns
// what it wrote to stderr when it died of SIGABRT, or "(did not abort)". The child runs only
// `fn` and exits; it starts no thread before the demand fails.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <string>

namespace crease::testing {

template <class Fn>
std::string abort_message(Fn&& fn) {
  int fds[2];
  if (pipe(fds) != 0) return "(no pipe)";
  const pid_t pid = fork();
  if (pid < 0) return "(no fork)";
  if (pid == 0) {
    dup2(fds[1], 2);
    fn();
    _exit(0);
  }
  close(fds[1]);
  std::string text;
  char buf[512];
  for (ssize_t n; (n = read(fds[0], buf, sizeof(buf))) > 0;) text.append(buf, static_cast<std::size_t>(n));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFSIGNALED(status) || WTERMSIG(status) != SIGABRT) return "(did not abort)";
  return text;
}

}  // namespace crease::testing
