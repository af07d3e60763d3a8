#include "plugins/sheet_score/state_recorder.h"

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "rt/alloc_guard.h"

using crease::SheetState;

TEST_CASE("every recorded frame is one JSON line in order, and queuing a frame allocates nothing") {
  const std::string path = "/tmp/crease-recorder-" + std::to_string(::getpid()) + ".jsonl";
  auto s = std::make_unique<SheetState>();
  s->nodes_u = 3;
  s->nodes_v = 2;
  s->width_mm = 210;
  s->height_mm = 297;
  std::uint64_t recorded = 0;
  {
    crease::sheet_score::StateRecorder rec(path, 1'000'000'000);
    for (int f = 1; f <= 20; ++f) {
      s->step = static_cast<std::uint64_t>(f);
      s->timestamp_ns = 1'000'000'000 + f * 16'666'667LL;
      for (int k = 0; k < 6; ++k) s->position_mm[k][2] = static_cast<float>(f);
      const auto before = crease::rt::rt_allocation_count();
      bool queued = false;
      {
        crease::rt::ScopedRtMark mark;
        queued = rec.record_rt(*s);
      }
      CHECK(crease::rt::rt_allocation_count() == before);
      if (!queued) usleep(20'000);  // the queue was full: the writer catches up (counted below)
    }
    s->nodes_u = 0;  // the safe value: no sheet, nothing recorded
    CHECK_FALSE(rec.record_rt(*s));
    rec.stop();
    CHECK(rec.recorded() + rec.dropped() == 20);
    CHECK(rec.recorded() >= 10);  // the writer drains every 10 ms: most frames find room
    recorded = rec.recorded();
  }
  std::ifstream in(path);
  std::string line;
  int lines = 0;
  std::uint64_t last = 0;
  while (std::getline(in, line)) {
    const auto j = nlohmann::json::parse(line);
    CHECK(j["grid"] == nlohmann::json::array({3, 2}));
    CHECK(j["nodes"].size() == 6);
    CHECK(j["size_mm"][1] == 297.0);
    const auto frame = j["frame"].get<std::uint64_t>();
    CHECK(frame > last);
    CHECK(j["nodes"][5][2].get<double>() == static_cast<double>(frame));
    CHECK(j["t"].get<double>() == doctest::Approx(static_cast<double>(frame) / 60).epsilon(1e-6));
    last = frame;
    ++lines;
  }
  CHECK(static_cast<std::uint64_t>(lines) == recorded);
  std::filesystem::remove(path);
}

TEST_CASE("a file that cannot be written is refused with its name") {
  try {
    crease::sheet_score::StateRecorder rec("/nonexistent-dir/x.jsonl", 0);
    FAIL("must throw");
  } catch (const std::exception& e) {
    CHECK(std::string(e.what()).find("/nonexistent-dir/x.jsonl") != std::string::npos);
  }
}
