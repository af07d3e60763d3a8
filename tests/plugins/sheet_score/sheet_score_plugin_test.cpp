// The sheet_score plugin in a loop: a model 2 mm above the truth scores 2 mm per frame, the
// figure names itself, and the recording has one line per model frame.
#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "core/plugin_host.h"
#include "core/port_types/figure.h"
#include "core/port_types/sheet_state.h"
#include "rt/alloc_guard.h"
#include "rt/clock.h"
#include "support/instance_spec.h"

using namespace std::chrono_literals;
using crease::Figure;
using crease::SheetState;

TEST_CASE("sheet_score: scores every model frame against the truth and records it") {
  const std::string path = "/tmp/crease-score-" + std::to_string(::getpid()) + ".jsonl";
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"model", 200.0, 0, -1});
  host.add_instance(
      crease::testing::instance_spec("score", "sheet_score", "model", 0, "{record: " + path + "}"));
  auto* model = host.ports().bind_latest_writer("sheet_state", crease::port_type_of<SheetState>(), "test");
  auto* truth = host.ports().bind_latest_writer("sheet_truth", crease::port_type_of<SheetState>(), "test");
  auto st = std::make_unique<SheetState>();
  st->nodes_u = 4;
  st->nodes_v = 3;
  truth->write(st.get(), crease::rt::now_ns());
  host.start();
  auto figure = [&] {
    Figure f{};
    host.ports().find_latest("tracking_error")->read(&f, 0);
    return f;
  };
  constexpr int kFrames = 30;
  for (int k = 1; k <= kFrames; ++k) {
    st->step = static_cast<std::uint64_t>(k);
    for (int n = 0; n < 12; ++n) st->position_mm[n][2] = 2.0f;
    const auto before = figure().count;
    model->write(st.get(), crease::rt::now_ns());
    for (int i = 0; i < 2000 && figure().count == before; ++i) std::this_thread::sleep_for(1ms);
  }
  const Figure f = figure();
  const auto allocs = crease::rt::rt_allocation_count();
  std::this_thread::sleep_for(50ms);  // steady state with nothing new: no allocation either
  CHECK(crease::rt::rt_allocation_count() == allocs);
  host.stop();
  CHECK(f.count == kFrames);
  CHECK(f.mean() == doctest::Approx(2.0));
  CHECK(f.last == doctest::Approx(2.0));
  CHECK(std::string(f.label) == "tracking error of sheet_state vs sheet_truth");
  CHECK(std::string(f.unit) == "mm");
  std::ifstream in(path);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) lines += nlohmann::json::parse(line)["grid"] == nlohmann::json::array({4, 3});
  CHECK(lines == kFrames);
  std::filesystem::remove(path);
}

TEST_CASE("sheet_score: a record file that cannot be written is a configuration error naming the key") {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"model", 60.0, 0, -1});
  try {
    host.add_instance(crease::testing::instance_spec("score", "sheet_score", "model", 0,
                                                     "{record: /nonexistent-dir/x.jsonl}"));
    FAIL("must throw");
  } catch (const std::exception& e) {
    const std::string what = e.what();
    CHECK(what.find("record") != std::string::npos);
    CHECK(what.find("test.yaml") != std::string::npos);
  }
}
