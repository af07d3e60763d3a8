// TaskTeam: every task runs once per run on our own threads, its effects visible to the caller
// after run(); exceptions come back to the caller; no thread but ours. Label `concurrency` too:
// under ThreadSanitizer the tasks' plain writes check the hand-over in both directions.
#include "plugins/vision/task_team.h"

#include <doctest/doctest.h>

#include <stdexcept>
#include <vector>

#include "support/abort_message.h"
#include "support/opencv_threads.h"

using crease::vision::TaskTeam;

TEST_CASE("each task runs exactly once per run, and the caller sees its effects") {
  crease::testing::own_threads_only();
  for (const int helpers : {0, 1, 3}) {
    CAPTURE(helpers);
    TaskTeam team(helpers);
    CHECK(team.helpers() == helpers);
    CHECK(crease::testing::process_threads() == 1 + helpers);
    std::vector<int> runs(7, 0);  // plain ints: one writer per run and element
    std::vector<int> last(7, -1);
    int expected = 0;
    for (int r = 0; r < 300; ++r) {
      const int n = 1 + r % 7;
      expected += n;
      auto task = [&](int k) {
        ++runs[static_cast<std::size_t>(k)];
        last[static_cast<std::size_t>(k)] = r;
      };
      team.run(n, task);
      for (int k = 0; k < n; ++k) REQUIRE(last[static_cast<std::size_t>(k)] == r);
    }
    int total = 0;
    for (const int c : runs) total += c;
    CHECK(total == expected);
    CHECK(runs[0] == 300);
    CHECK(runs[6] == 42);
  }
}

TEST_CASE("a task's exception reaches the caller after the others ran; the team goes on") {
  TaskTeam team(2);
  std::vector<int> done(5, 0);
  auto failing = [&](int k) {
    done[static_cast<std::size_t>(k)] = 1;
    if (k == 3) throw std::runtime_error("camera 3 failed");
  };
  CHECK_THROWS_WITH_AS(team.run(5, failing), "camera 3 failed", std::runtime_error);
  CHECK(done == std::vector<int>{1, 1, 1, 1, 1});
  int sum = 0;
  auto add = [&](int k) {
    if (k == 0) sum = 1;
  };
  team.run(4, add);
  CHECK(sum == 1);
  CHECK(crease::testing::abort_message([] { TaskTeam t(-1); }).find("negative number of helper threads") !=
        std::string::npos);
}
