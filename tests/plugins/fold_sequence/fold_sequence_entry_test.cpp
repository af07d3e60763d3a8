// The fold_sequence library as creased loads it: in a real 1 kHz loop of the plugin host, the
// `command` tunable set through the host's param path (what `creasectl sequence start` sends)
// asks for the start; with no controller answering, the start's guard keeps it in idle and
// nothing is sent. A bad fold file is a load error naming it. No timing thresholds: the waits
// are bounded in count only.
#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <string>
#include <thread>

#include "core/errors.h"
#include "core/plugin_host.h"
#include "core/port.h"
#include "core/port_types/hand_goal.h"
#include "core/port_types/sequence_status.h"
#include "plugins/fold_sequence/fold_sequence_plugin.h"
#include "support/instance_spec.h"

using namespace std::chrono_literals;

namespace {

crease::InstanceSpec spec(const std::string& fold) {
  return crease::testing::instance_spec("fold", "fold_sequence", "control", 0,
                                        "{fold: " + fold + "}");
}

crease::SequenceStatus status(const crease::PluginHost& host) {
  crease::SequenceStatus s{};
  const auto* ch = host.ports().find_latest("sequence_status");
  if (ch != nullptr) (void)ch->read(&s, 0);
  return s;
}

template <class Pred>
bool wait(Pred pred) {
  for (int i = 0; i < 20000; ++i) {
    if (pred()) return true;
    std::this_thread::sleep_for(1ms);
  }
  return pred();
}

}  // namespace

TEST_CASE("loaded by the host: started through its param path, it waits in idle while no controller answers") {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"control", 1000.0, 0, -1});
  host.add_instance(spec(std::string(CREASE_SOURCE_DIR) + "/config/folds/half.yaml"));
  crease::QueueInput<crease::HandGoal> hand_r(host.ports().bind_queue_reader(
      "hand_r_goal", crease::port_type_of<crease::HandGoal>(), "test", crease::fold::FoldSequencePlugin::kHandGoalQueue));
  host.start();
  REQUIRE(wait([&] { return std::string(status(host).path) == "idle"; }));
  CHECK(std::string(status(host).fold) == "half");
  CHECK_FALSE(host.set_param("fold", "command", 1.5).empty());  // not a command
  CHECK(host.set_param("fold", "command", 1.0).empty());        // start
  REQUIRE(wait([&] { return std::string(status(host).why) == "start: waiting for the controllers and the sheet"; }));
  for (int i = 0; i < 50; ++i) std::this_thread::sleep_for(1ms);
  const crease::SequenceStatus s = status(host);
  CHECK(std::string(s.path) == "idle");  // the start's guard: nothing answers, so it does not start
  CHECK(s.aborts == 0);
  host.stop();
  crease::HandGoal g{};
  CHECK_FALSE(hand_r.try_pop(g));  // nothing sent
}

TEST_CASE("a malformed fold file is a load error naming the file and key") {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"control", 1000.0, 0, -1});
  const std::string missing = std::string(CREASE_SOURCE_DIR) + "/config/folds/none.yaml";
  try {
    host.add_instance(spec(missing));
    FAIL("loaded");
  } catch (const std::exception& e) {
    CHECK(std::string(e.what()).find(missing) != std::string::npos);
  }
}
