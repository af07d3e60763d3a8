// The sheet_truth plugin beside a sheet_model in one loop: the truth folds, and tells the model
// nothing about it (no crease reaches the model: the robot has no such oracle).
#include <doctest/doctest.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "core/plugin_host.h"
#include "core/port_types/sheet_state.h"
#include "support/instance_spec.h"

using namespace std::chrono_literals;
using crease::SheetState;

TEST_CASE("sheet_truth folds without announcing a crease to the model") {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"model", 60.0, 0, -1});
  auto add = [&](const std::string& name, const std::string& library, int order,
                 const std::string& yaml) {
    host.add_instance(crease::testing::instance_spec(name, library, "model", order, yaml));
  };
  add("truth", "sheet_truth", 1, "{start_s: 0, origin_x_mm: 0, origin_y_mm: 297}");
  add("sheet", "sheet_model", 10, "{}");
  host.start();
  auto truth = std::make_unique<SheetState>(), model = std::make_unique<SheetState>();
  // Until the flap's far edge (row 0) is well up: the fold is under way (theta > 0 from t = 0).
  bool folding = false;
  for (int i = 0; i < 20000 && !folding; ++i) {
    std::this_thread::sleep_for(1ms);
    folding = host.ports().find_latest("sheet_truth")->read(truth.get(), 0).has_data() && truth->nodes_u == 15 &&
              truth->position_mm[7][2] > 30.0f;
  }
  REQUIRE(folding);
  std::this_thread::sleep_for(200ms);  // a few more model frames: an announced crease would be in
  REQUIRE(host.ports().find_latest("sheet_state")->read(model.get(), 0).has_data());
  host.stop();
  CHECK(model->nodes_u == 15);
  CHECK(model->step > 0);
  CHECK(model->crease_count == 0);
}
