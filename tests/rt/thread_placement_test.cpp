// rt/thread_placement: CPU lists, the non-RT set inherited by threads made after it, a thread
// placed and named explicitly, and the process's threads listed with their placement.
#include "rt/thread_placement.h"

#include <doctest/doctest.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <thread>

using namespace crease::rt;

namespace {
std::vector<int> my_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  REQUIRE(sched_getaffinity(0, sizeof(set), &set) == 0);
  std::vector<int> out;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) out.push_back(c);
  return out;
}

const ThreadInfo* find_named(const std::vector<ThreadInfo>& ts, const std::string& name) {
  for (const ThreadInfo& t : ts)
    if (t.name == name) return &t;
  return nullptr;
}
}  // namespace

TEST_CASE("CPU lists parse and print as the kernel writes them") {
  CHECK(parse_cpu_list("0") == std::vector<int>{0});
  CHECK(parse_cpu_list("0,2-4") == std::vector<int>{0, 2, 3, 4});
  CHECK(parse_cpu_list("3,1,1") == std::vector<int>{1, 3});
  CHECK(parse_cpu_list("a").empty());
  CHECK(parse_cpu_list("2-1").empty());
  CHECK(parse_cpu_list("1,-2").empty());
  CHECK(format_cpu_list({0, 2, 3, 4, 7}) == "0,2-4,7");
  CHECK(format_cpu_list({}) == "");
  CHECK(format_cpu_list(parse_cpu_list("0-3,8")) == "0-3,8");
}

TEST_CASE("the non-RT set moves the caller, threads made later start there, a placed thread is named") {
  const std::vector<int> all = process_cpus();
  REQUIRE_FALSE(all.empty());
  const std::vector<int> one{all.back()};  // a strict subset on a machine of two or more CPUs

  const SetupStep step = set_non_rt_cpus(one);
  CHECK(step.applied);
  CHECK(non_rt_cpus() == one);
  CHECK(my_cpus() == one);  // the caller moved

  std::vector<int> inherited;
  std::thread([&] { inherited = my_cpus(); }).join();
  CHECK(inherited == one);  // made after the call: starts on the set

  // A thread that was elsewhere (here: moved to every CPU) is brought back and named.
  std::vector<int> placed;
  std::vector<ThreadInfo> seen;
  std::thread([&] {
    cpu_set_t every;
    CPU_ZERO(&every);
    for (int c : all) CPU_SET(c, &every);
    REQUIRE(pthread_setaffinity_np(pthread_self(), sizeof(every), &every) == 0);
    place_this_thread_non_rt("crease-test-place-long-name");
    placed = my_cpus();
    seen = list_threads();
  }).join();
  CHECK(placed == one);
  const ThreadInfo* t = find_named(seen, "crease-test-pla");  // 15 characters, as the kernel keeps
  REQUIRE(t != nullptr);
  CHECK(t->cpus == one);
  CHECK(t->policy == "other");
  CHECK(t->priority == 0);
  CHECK(std::find(one.begin(), one.end(), t->last_cpu) != one.end());

  // Every CPU again: the next test (and the process) is not left on one CPU.
  CHECK(set_non_rt_cpus(all).applied);
  CHECK(my_cpus() == all);
}

TEST_CASE("an empty or impossible set is refused with a reason and moves nothing") {
  const std::vector<int> before = my_cpus();
  const SetupStep empty = set_non_rt_cpus({});
  CHECK_FALSE(empty.applied);
  CHECK(empty.why.find("no CPU") != std::string::npos);
  const SetupStep far = set_non_rt_cpus({CPU_SETSIZE + 5});
  CHECK_FALSE(far.applied);
  CHECK(my_cpus() == before);
}

TEST_CASE("list_threads sees the calling thread with its scheduling") {
  const std::vector<ThreadInfo> ts = list_threads();
  REQUIRE_FALSE(ts.empty());
  bool found_self = false;
  const int self = static_cast<int>(gettid());
  for (const ThreadInfo& t : ts) {
    if (t.tid != self) continue;
    found_self = true;
    CHECK_FALSE(t.cpus.empty());
    CHECK_FALSE(t.name.empty());
  }
  CHECK(found_self);
}
