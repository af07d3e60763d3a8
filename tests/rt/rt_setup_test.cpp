#include "rt/rt_setup.h"

#include <doctest/doctest.h>

TEST_CASE("memory locking is applied or refused with a reason") {
  const auto step = crease::rt::lock_memory(1 << 20);
  CHECK_FALSE(step.what.empty());
  if (!step.applied) CHECK_FALSE(step.why.empty());
}

TEST_CASE("the dma latency request is applied or refused with a reason") {
  crease::rt::DmaLatencyRequest req;
  const auto step = req.request(0);
  if (!step.applied) CHECK(step.why.find("errno") != std::string::npos);
}
