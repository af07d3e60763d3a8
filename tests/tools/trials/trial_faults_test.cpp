// crease-trials --faults (tools/trials/trial_run.h enable_faults): the simulated robot's
// configuration gets the world's bus faults and the cameras' dropouts, seeded by the trial; a
// configuration without a world to inject into is refused.
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>

#include "core/config/daemon_config.h"
#include "tools/trials/trial_run.h"

using namespace crease;

namespace {
std::string param(const config::DaemonConfig& c, const std::string& library, const std::string& key) {
  for (const auto& p : c.plugins)
    if (p.library == library && p.params[key]) return p.params[key].as<std::string>();
  return "";
}
}  // namespace

TEST_CASE("--faults turns on the world's bus faults and the cameras' dropouts, seeded by the trial") {
  config::DaemonConfig c = config::load_daemon_config(CREASE_SOURCE_DIR "/config/sim.yaml");
  CHECK(param(c, "sim_world", "faults").empty());
  CHECK(param(c, "camera_sim", "dropouts").empty());
  trials::enable_faults(c, 7);
  CHECK(param(c, "sim_world", "faults") == "true");
  CHECK(param(c, "sim_world", "fault_seed") == "7");
  CHECK(param(c, "camera_sim", "dropouts") == "3");
  CHECK(param(c, "camera_sim", "dropout_seed") == "7");

  config::DaemonConfig none = config::load_daemon_config(CREASE_SOURCE_DIR "/config/sim.yaml");
  std::erase_if(none.plugins, [](const config::PluginConfig& p) { return p.library == "sim_world"; });
  CHECK_THROWS_AS(trials::enable_faults(none, 7), std::runtime_error);
}
