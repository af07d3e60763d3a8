// config/sim.yaml's folding sequence against the simulated world, in process with its loops in
// real time (as sim_controllers_test.cpp): started as `creasectl sequence start` starts it (its
// guard: every controller answering, the sheet seen by vision and the model), its first state's
// goals go through the real controllers and drivers on the mocked buses, and the sequence moves
// on when they answer (the approach reached, then the descent; or refused, then the abort),
// never for a fault of the simulated link; its retreat (or `creasectl sequence abort`'s) leaves
// the hands open and pressing nothing and the arms clear, lifted from where they were. Scored
// from the world's truth (world_state: fingertip poses and forces, the hands' joint angles).
// Every transition is on the run's timeline. Failing variant: the arm goals reach no arm.
// It prints the simulated link as it saw it (sim_link_watch.h: each device port's oldest age
// and first fault, the world's lag) and the loops' timing, so a device_fault names its port.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "core/config/daemon_config.h"
#include "core/daemon/daemon.h"
#include "core/daemon/report_builder.h"
#include "core/port_types/arm_goal.h"
#include "core/port_types/sequence_status.h"
#include "core/port_types/world_state.h"
#include "rt/latest.h"
#include "rt/thread_placement.h"
#include "tests/config/sim_link_watch.h"

using namespace crease;

namespace {

template <class T>
rt::LatestReader<T> reader(PluginHost& host, const std::string& port) {
  const rt::LatestChannel* ch = host.ports().find_latest(port);
  REQUIRE_MESSAGE(ch != nullptr, port);
  return rt::LatestReader<T>(ch);
}

std::string path_of(const SequenceStatus& s) { return std::string(s.path, strnlen(s.path, sizeof s.path)); }

// The half fold's shifting hand (config/folds/half.yaml: the right, rubber-covered one presses and
// slides the sheet, seed 000 Fig. 7a).
constexpr int kShifting = 0;

// The world's shifting index pad: its height (mm) and the largest normal force of any fingertip.
struct Tips {
  double shifting_ff_z_mm = 0, max_force_n = 0, min_z_mm = 1e9, max_joint_rad = 0;
  bool touching = false;
};
Tips tips(const WorldState& w) {
  Tips t;
  t.shifting_ff_z_mm = w.hand[kShifting].tip[0].position_mm[2];
  for (const WorldHand& h : w.hand) {
    t.touching = t.touching || h.palm_contact != 0;
    for (const WorldFingertip& f : h.tip) {
      t.max_force_n = std::max(t.max_force_n, double(f.normal_force_n));
      t.min_z_mm = std::min(t.min_z_mm, double(f.position_mm[2]));
      t.touching = t.touching || f.contact != 0;
    }
    for (float q : h.joint_rad) t.max_joint_rad = std::max(t.max_joint_rad, double(std::fabs(q)));
  }
  return t;
}

}  // namespace

TEST_CASE("config/sim.yaml's folding sequence runs its first states against the world and aborts safely") {
  auto cfg = config::load_daemon_config(CREASE_SOURCE_DIR "/config/sim.yaml");
  bool wired = true;
  SUBCASE("as shipped") {}
  SUBCASE("failing variant: the sequence's arm goals reach no arm (nothing moves in the world)") {
    wired = false;
    for (auto& p : cfg.plugins)
      if (p.name == "fold") {
        p.ports["arm_r_goal"] = "nowhere_r.goal";
        p.ports["arm_l_goal"] = "nowhere_l.goal";
      }
  }
  daemon::Options opts;
  opts.plugin_dirs = {CREASE_PLUGIN_DIR};
  daemon::Daemon daemon(std::move(cfg), opts);
  PluginHost& host = daemon.host();
  auto status = reader<SequenceStatus>(host, "fold.status");
  auto world = reader<WorldState>(host, "world_state");
  auto motion_r = reader<ArmMotionStatus>(host, "arm_r.motion_status");
  host.start();
  test::SimLinkWatch links(host);

  // creasectl sequence start: taken once its guard passes (every controller answering, the
  // contact states healthy, both hands commanded, the sheet seen by vision and the model).
  REQUIRE(host.set_param("fold", "command", 1.0).empty());
  for (int i = 0; i < 30000 && status.value().phase == SequenceStatus::idle; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (i % 50 == 0) host.poll();  // as creased does: the loops' events and logs
    status.poll();
    links.poll();
  }
  if (status.value().phase != SequenceStatus::running && motion_r.poll().has_data())
    MESSAGE("not running: " << path_of(status.value()) << "; arm_r's last refusal: reason "
                            << int(motion_r.value().last_refusal) << " (ArmMotionReason)");
  REQUIRE(status.value().phase == SequenceStatus::running);
  REQUIRE(world.poll().has_data());
  const Tips start = tips(world.value());
  MESSAGE("started: " << path_of(status.value()) << ", the shifting index pad "
                      << start.shifting_ff_z_mm << " mm up");

  // Its first state: both hands to the open posture (force_X), the shifting arm's approach above
  // the sheet (motion_l, solved ahead against the real arm_state). It moves on when arm_motion
  // answers: reached (then the contact descent), or refused. Until the press, at most 40 s.
  std::string path = path_of(status.value()), deepest = path;
  double lowest_mm = start.shifting_ff_z_mm, press_force_n = 0;
  const auto deeper = [](const std::string& p) {
    return p == "fold/shift/press" || p == "fold/shift/slide" || p == "fold/shift/check" ||
           p.rfind("fold/grasp", 0) == 0;
  };
  const int limit_ms = wired ? 40000 : 5000;
  for (int i = 0; i < limit_ms; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (i % 50 == 0) host.poll();
    status.poll();
    links.poll();
    if (world.poll().is_new()) {
      const Tips t = tips(world.value());
      lowest_mm = std::min(lowest_mm, t.shifting_ff_z_mm);
      if (deeper(path))
        press_force_n =
            std::max(press_force_n, double(world.value().hand[kShifting].tip[0].normal_force_n));
    }
    if (path_of(status.value()) != path) {
      path = path_of(status.value());
      MESSAGE(i << " ms: " << path << " (" << status.value().why << ")");
      if (path.rfind("fold/", 0) == 0) deepest = path;
    }
    if (status.value().phase != SequenceStatus::running) break;
    if (deeper(path) && press_force_n > 0.5) break;
  }
  const auto own_reason = static_cast<int>(status.value().abort_reason);
  std::string loops;
  for (const Loop* l : host.loops())
    loops += l->spec().name + ": " + std::to_string(l->timing().overruns.load()) + " overruns, " +
             std::to_string(l->timing().late_wakes.load()) + " late wakes, wake-up latency up to " +
             std::to_string(static_cast<double>(l->timing().wakeup_latency.max_ns()) / 1e6) + " ms, body up to " +
             std::to_string(static_cast<double>(l->timing().execution.max_ns()) / 1e6) + " ms, " +
             std::to_string(l->timing().missed_periods.load()) + " missed periods\n";
  for (const rt::ThreadInfo& th : rt::list_threads())
    loops += th.name + " " + th.policy + " " + std::to_string(th.priority) + " cpus " + rt::format_cpu_list(th.cpus) + "; ";
  MESSAGE("the simulated link until here:\n" << links.summary() << loops);
  MESSAGE("deepest state " << deepest << ", the shifting index pad down to " << lowest_mm
                           << " mm, pressing " << press_force_n << " N; "
                           << (status.value().phase == SequenceStatus::running
                                   ? std::string("running")
                                   : "aborted: " + std::string(status.value().why)));
  if (!wired) {
    // Its motion never answers: it does not leave the approach for an answer of arm_motion
    // (reached, unreachable; a fault of a loaded machine may still abort it) and nothing moves
    // in the world.
    CHECK(deepest == "fold/shift/approach");
    CHECK(own_reason != 7);  // unreachable: arm_motion's answer, which never came
    CHECK(std::fabs(lowest_mm - start.shifting_ff_z_mm) < 1.0);
    host.stop();
    return;
  }
  // The controllers answered the first state's goals: the sequence left the approach, into the
  // descent when arm_motion reached it, into the abort when it refused it. Never for a fault of
  // the simulated link (device_fault, a goal refused as arm_not_ready): the shared machine's
  // late answers are within the tolerance config/sim.yaml gives the link.
  CHECK((path != "fold/shift/approach" || status.value().phase != SequenceStatus::running));
  CHECK(own_reason != 4);  // device_fault
  CHECK(own_reason != 8);  // goal_refused
  const bool moved = deepest != "fold/shift/approach";
  if (moved) CHECK(lowest_mm < start.shifting_ff_z_mm - 20.0);  // the world's fingertip went down

  // creasectl sequence abort (or the sequence's own): stop, open, lift, park, until aborted.
  REQUIRE(world.poll().has_data());
  const Tips at_abort = tips(world.value());
  if (status.value().phase == SequenceStatus::running) REQUIRE(host.set_param("fold", "command", 4.0).empty());
  for (int i = 0; i < 90000 && path_of(status.value()) != "aborted"; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (i % 50 == 0) host.poll();
    status.poll();
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  status.poll();
  world.poll();
  const Tips end = tips(world.value());
  const std::uint32_t transitions = status.value().transitions;
  host.stop();
  host.poll();
  // Every transition is on the run's timeline: the sequence's marks, as the report lists them.
  std::vector<std::string> marks;
  for (const HostEvent& e : host.events())
    if (e.type == HostEvent::Type::mark && e.instance == "fold") marks.push_back(e.detail);
  CHECK(marks.size() == transitions);
  REQUIRE(!marks.empty());
  CHECK(marks.front().rfind("fold/shift/approach: ", 0) == 0);
  CHECK(marks.back().rfind("aborted: ", 0) == 0);
  int in_report = 0;
  for (const auto& e : daemon::build_report(host, daemon::RunFacts{}).events) in_report += e.kind == "mark";
  CHECK(in_report == static_cast<int>(marks.size()));
  MESSAGE("aborted: " << path_of(status.value()) << " (" << status.value().why << "); the fingertips from "
                      << at_abort.min_z_mm << " to " << end.min_z_mm << " mm up, pressing " << end.max_force_n
                      << " N, joints at most " << end.max_joint_rad << " rad from open");
  REQUIRE(status.value().phase == SequenceStatus::aborted);
  CHECK(path_of(status.value()) == "aborted");
  CHECK_FALSE(end.touching);          // nothing left pressing or pinching
  CHECK(end.max_force_n < 0.05);
  CHECK(end.max_joint_rad < 0.05);    // the hands open (the fold's open posture: every joint 0)
  CHECK(end.min_z_mm > 100.0);        // the arms clear of the sheet (parked: palms 300 mm up)
  if (moved) CHECK(end.min_z_mm > at_abort.min_z_mm + 25.0);  // lifted from where it was
}
