#include "rt/alloc_guard.h"

#include <doctest/doctest.h>

#include <memory>
#include <thread>
#include <vector>

TEST_CASE("the hooks are linked into tests") { CHECK(crease::rt::alloc_hooks_installed()); }

TEST_CASE("allocations on RT-marked threads are counted; others are not") {
  const auto before = crease::rt::rt_allocation_count();
  auto p = std::make_unique<int>(1);  // not RT: not counted
  CHECK(crease::rt::rt_allocation_count() == before);
  {
    crease::rt::ScopedRtMark mark;
    auto q = std::make_unique<int>(2);
    std::vector<double> v(10);
    CHECK(crease::rt::rt_allocation_count() == before + 2);
  }
  CHECK(crease::rt::rt_free_count() >= 2);
  CHECK_FALSE(crease::rt::this_thread_is_rt());
}

TEST_CASE("the mark is per thread") {
  crease::rt::ScopedRtMark mark;
  bool other_is_rt = true;
  std::thread([&] { other_is_rt = crease::rt::this_thread_is_rt(); }).join();
  CHECK_FALSE(other_is_rt);
  CHECK(crease::rt::this_thread_is_rt());
}

TEST_CASE("each thread has its own count, of its RT-marked allocations only") {
  const std::uint64_t* mine = crease::rt::this_thread_rt_allocations();
  const std::uint64_t before = *mine;
  auto not_counted = std::make_unique<int>(0);  // not RT-marked
  CHECK(*mine == before);
  std::uint64_t other_count = 99;
  std::vector<std::unique_ptr<int>> kept;  // escapes: the allocations cannot be elided
  kept.reserve(3);
  std::thread([&] {
    crease::rt::ScopedRtMark mark;
    const std::uint64_t* theirs = crease::rt::this_thread_rt_allocations();
    const std::uint64_t at_start = *theirs;
    kept.push_back(std::make_unique<int>(1));
    kept.push_back(std::make_unique<int>(2));
    other_count = *theirs - at_start;
  }).join();
  CHECK(other_count == 2);
  CHECK(*mine == before);  // the other thread's allocations are not this one's
  {
    crease::rt::ScopedRtMark mark;
    kept.push_back(std::make_unique<int>(3));  // within the reserved capacity: one allocation
    CHECK(*mine == before + 1);
  }
}
