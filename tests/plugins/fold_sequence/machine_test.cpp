// The machine alone (no ports): what the plugin tests do not reach through the rig: a memory
// refused on restore, a lost command aborting with its reason, the status texts.
#include "plugins/fold_sequence/machine.h"

#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace crease;
using namespace crease::fold;

namespace {
FoldSpec half() { return load_fold_file(std::string(CREASE_SOURCE_DIR) + "/config/folds/half.yaml"); }

// Controllers that answer (fresh, healthy) but never finish anything.
struct Quiet {
  ArmMotionStatus arm[2]{};
  HandControlStatus hand[2]{};
  ContactState contact[2]{};
  std::unique_ptr<SheetState> sheet = std::make_unique<SheetState>();
  Sensing at(std::int64_t now) {
    Sensing in;
    in.now_ns = now;
    for (int s = 0; s < 2; ++s) {
      arm[s].timestamp_ns = hand[s].timestamp_ns = contact[s].timestamp_ns = now;
      contact[s].healthy = contact[s].armed = 1;
      hand[s].commanding = 1;
      in.arm[s] = &arm[s];
      in.hand[s] = &hand[s];
      in.contact[s] = &contact[s];
    }
    sheet->timestamp_ns = now;
    sheet->observations = 10;
    in.sheet = sheet.get();
    return in;
  }
};
}  // namespace

TEST_CASE("restore refuses a memory of another version, fold or a superstate") {
  const FoldSpec f = half();
  Machine m(f);
  Memory saved = m.memory();
  saved.leaf = S::follow_via;
  saved.via = 2;
  Memory bad = saved;
  bad.version = Memory::kVersion + 1;
  CHECK_FALSE(m.restore(bad));
  bad = saved;
  bad.spec_hash ^= 1;
  CHECK_FALSE(m.restore(bad));
  bad = saved;
  bad.leaf = S::bend;  // not a leaf
  CHECK_FALSE(m.restore(bad));
  CHECK(m.memory().leaf == S::idle);  // nothing changed
  REQUIRE(m.restore(saved));
  SequenceStatus st;
  m.fill_status(st, 5);
  CHECK(std::string(st.path) == "fold/bend/follow_via[2]");
  CHECK(std::string(st.fold) == "half");
}

TEST_CASE("a command the plugin could not queue aborts the fold with command_lost") {
  const FoldSpec f = half();
  Machine m(f);
  Quiet q;
  Outbox out;
  m.command(Command::start);
  m.step(q.at(1'000'000), out);
  SequenceStatus st;
  m.fill_status(st, 1'000'000);
  CHECK(std::string(st.path) == "fold/shift/approach");
  CHECK(std::string(st.why) == "start");
  CHECK(out.arm_count[kPinching] == 1);  // half.yaml: the pinching (rubber) hand shifts
  CHECK(out.arm_count[kFixing] == 0);
  CHECK(out.hand_count[kFixing] == 1);
  CHECK(out.hand_count[kPinching] == 1);
  m.step(q.at(2'000'000), out);  // nothing finished: it waits
  m.fill_status(st, 2'000'000);
  CHECK(std::string(st.path) == "fold/shift/approach");
  CHECK(out.arm_count[kPinching] == 0);
  m.fail(Reason::command_lost);
  m.step(q.at(3'000'000), out);
  m.fill_status(st, 3'000'000);
  CHECK(std::string(st.path) == "abort/stop");
  CHECK(std::string(st.why) == "abort: command_lost");
  CHECK(st.abort_reason == static_cast<std::uint8_t>(Reason::command_lost));
  CHECK(st.phase == SequenceStatus::aborted);
  // The retreat's first goals: hold to both hands, stop to both arms.
  CHECK(out.hand[kFixing][0].mode == HandMode::hold);
  CHECK(out.hand[kPinching][0].mode == HandMode::hold);
  CHECK(out.arm[kFixing][0].kind == ArmGoal::stop);
  CHECK(out.arm[kPinching][0].kind == ArmGoal::stop);
}

TEST_CASE("outside the fold, pause, resume and abort do nothing; start only from a resting state") {
  const FoldSpec f = half();
  Machine m(f);
  Quiet q;
  Outbox out;
  for (Command c : {Command::pause, Command::resume, Command::abort}) {
    m.command(c);
    m.step(q.at(1'000'000), out);
    CHECK(m.memory().leaf == S::idle);
    CHECK(out.arm_count[0] + out.arm_count[1] + out.hand_count[0] + out.hand_count[1] == 0);
  }
  CHECK(m.phase() == SequenceStatus::idle);
}

TEST_CASE(
    "an abort on a fault names the input it came from in the status's why, by the side that plays "
    "the role") {
  // half.yaml: the right hand pinches, the left fixes; swapped, the same faults name the other
  // side.
  const FoldSpec f = half();
  REQUIRE(f.pinching_side == 0);
  FoldSpec swapped = f;
  swapped.pinching_side = 1;
  struct Case {
    const char* name;
    void (*spoil)(Quiet&, std::int64_t now);
    const char* why;          // half.yaml
    const char* why_swapped;  // the pinching hand the left
    Reason reason;
  };
  const Case cases[] = {
      {"fixing contact unhealthy", [](Quiet& q, std::int64_t) { q.contact[kFixing].healthy = 0; },
       "abort: device_fault: contact_l unhealthy", "abort: device_fault: contact_r unhealthy",
       Reason::device_fault},
      {"pinching hand's status 60 ms old",
       [](Quiet& q, std::int64_t now) { q.hand[kPinching].timestamp_ns = now - 60'000'000; },
       "abort: device_fault: hand_r status stale", "abort: device_fault: hand_l status stale",
       Reason::device_fault},
      {"pinching hand's tactile stale",
       [](Quiet& q, std::int64_t) {
         q.hand[kPinching].inhibits = 1;
         q.hand[kPinching].inhibit = HandInhibit::tactile_stale;
       },
       "abort: device_fault: hand_r tactile stale", "abort: device_fault: hand_l tactile stale",
       Reason::device_fault},
      {"fixing hand over its force limit",
       [](Quiet& q, std::int64_t) {
         q.hand[kFixing].inhibits = 1;
         q.hand[kFixing].inhibit = HandInhibit::force_limit;
       },
       "abort: force_limit: hand_l force limit", "abort: force_limit: hand_r force limit",
       Reason::force_limit},
  };
  for (const Case& c : cases)
    for (const bool swap : {false, true}) {
      CAPTURE(c.name);
      CAPTURE(swap);
      Machine m(swap ? swapped : f);
      Quiet q;
      Outbox out;
      m.command(Command::start);
      m.step(q.at(1'000'000), out);
      Sensing in = q.at(2'000'000);
      c.spoil(q, 2'000'000);
      m.step(in, out);
      SequenceStatus st;
      m.fill_status(st, 2'000'000);
      CHECK(std::string(st.path) == "abort/stop");
      CHECK(std::string(st.why) == (swap ? c.why_swapped : c.why));
      CHECK(st.abort_reason == static_cast<std::uint8_t>(c.reason));
    }
}

TEST_CASE("an abort from the grasp's reach backs the pinching hand out the way it went in") {
  // half.yaml's reach: from above beyond the far edge (segment 0) down to 35.5 mm under the table
  // top (path 0), in under the overhang (segment 1, to path 1), up to the sheet (segment 2).
  // Lifted straight up from under the overhang the hand rose into the table from below (a
  // trial: the index 40 mm under the top, pressing 1026 N).
  const FoldSpec f = half();
  REQUIRE(f.grasp_path_count == 2);
  struct Case {
    S from;
    int segment;  // the pinching arm's, when the abort began (-1: its status about another goal)
    int back;     // path points backed through before above_mm (-1: lifted straight up)
  };
  for (const Case c :
       {Case{S::grasp_reach, 2, 2}, Case{S::grasp_reach, 1, 1}, Case{S::grasp_reach, 0, 0},
        Case{S::grasp_reach, -1, 0}, Case{S::grasp_pinch, -1, 2}, Case{S::follow_via, 3, -1}}) {
    CAPTURE(static_cast<int>(c.from));
    CAPTURE(c.segment);
    Machine m(f);
    Memory saved = m.memory();
    saved.leaf = c.from;
    saved.arm_has_target[kFixing] = saved.arm_has_target[kPinching] = 1;
    saved.arm_tool[kPinching] = f.grasp_tool;
    saved.arm_id[kPinching] = 77;
    REQUIRE(m.restore(saved));
    Quiet q;
    q.arm[kPinching].goal_id = c.segment >= 0 ? 77 : 76;
    q.arm[kPinching].segment = static_cast<std::uint8_t>(c.segment >= 0 ? c.segment : 0);
    q.arm[kPinching].state = ArmMotionStatus::running;
    Outbox out;
    std::int64_t now = 1'000'000;
    m.fail(Reason::force_limit);
    m.step(q.at(now), out);
    REQUIRE(m.memory().leaf == S::abort_stop);
    CHECK(m.memory().aborted_from == c.from);
    for (int k = 0; k < 10 && m.memory().leaf != S::abort_lift; ++k) {
      now += 30'000'000'000;  // past every timeout: stop, open
      m.step(q.at(now), out);
    }
    REQUIRE(m.memory().leaf == S::abort_lift);
    REQUIRE(out.arm_count[kPinching] == 1);
    REQUIRE(out.arm_count[kFixing] == 1);
    CHECK(out.arm[kFixing][0].frame == ArmGoal::measured);  // the fixing hand lifts
    const ArmGoal& pin = out.arm[kPinching][0];
    if (c.back < 0) {
      CHECK(pin.frame == ArmGoal::measured);  // straight up
      CHECK(pin.point_count == 1);
      continue;
    }
    REQUIRE(pin.frame == ArmGoal::sheet);
    CHECK(pin.kind == ArmGoal::retreat);  // arm_motion takes it while the hand retreats
    REQUIRE(pin.point_count == c.back + 1);
    for (int k = 0; k < c.back; ++k)
      for (int i = 0; i < 3; ++i)
        CHECK(pin.position_mm[k][i] == doctest::Approx(f.grasp_path_mm[c.back - 1 - k][i]));
    for (int i = 0; i < 3; ++i)
      CHECK(pin.position_mm[c.back][i] == doctest::Approx(f.grasp_above_mm[i]));
  }
}

TEST_CASE(
    "an abort from the bend or the lay backs the pinching hand out through the via points it "
    "passed, then the way it came") {
  // Lifted 30 mm and parked from a pinch the bend had turned, the hand swept through the table
  // (trials: 3443 N; 17.7 N and the park timed out). Still by the grasp (the motion to the
  // first via point), it lifts straight up as before.
  const FoldSpec f = half();
  REQUIRE(f.via_count == 8);
  REQUIRE(f.grasp_above_via_count == 1);
  struct Case {
    S from;
    int via;                // the via point the pinch was moving to
    std::vector<int> back;  // the via points backed through, in order (empty: lifted)
  };
  for (const Case& c : {Case{S::follow_via, 3, {2, 1, 0}}, Case{S::follow_via, 1, {0}},
                        Case{S::layer_lay, 7, {7, 5, 3, 1, 0}}, Case{S::follow_via, 0, {}},
                        Case{S::bend_crease, 0, {}}}) {
    CAPTURE(static_cast<int>(c.from));
    CAPTURE(c.via);
    Machine m(f);
    Memory saved = m.memory();
    saved.leaf = c.from;
    saved.via = static_cast<std::uint8_t>(c.via);
    saved.arm_has_target[kFixing] = saved.arm_has_target[kPinching] = 1;
    saved.arm_tool[kPinching] = f.grasp_tool;
    REQUIRE(m.restore(saved));
    Quiet q;
    // The sheet as the simulated robot lays it (corner (0, 0) at (105, -148.5), u along -x, v
    // along +y): above_via, a world point, goes out as the sheet point [-95, -1.5, 300 up].
    q.sheet->nodes_u = q.sheet->nodes_v = 3;
    q.sheet->width_mm = 210;
    q.sheet->height_mm = 297;
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        q.sheet->position_mm[j * 3 + i][0] = static_cast<float>(105.0 - 105.0 * i);
        q.sheet->position_mm[j * 3 + i][1] = static_cast<float>(-148.5 + 148.5 * j);
      }
    Outbox out;
    std::int64_t now = 1'000'000;
    m.fail(Reason::pinch_lost);
    m.step(q.at(now), out);
    REQUIRE(m.memory().leaf == S::abort_stop);
    HandGoal opening{};  // the pinching hand's goal as the retreat opens the hands
    for (int k = 0; k < 10 && m.memory().leaf != S::abort_lift; ++k) {
      now += 30'000'000'000;  // past every timeout: stop, open
      m.step(q.at(now), out);
      if (m.memory().leaf == S::abort_open && out.hand_count[kPinching] > 0)
        opening = out.hand[kPinching][0];
    }
    REQUIRE(m.memory().leaf == S::abort_lift);
    // Backed out of the bend, the pinch lets go with its thumb only (prepinch: the index, whose
    // pad frame the way back is planned for, keeps its curl); otherwise the hand opens.
    REQUIRE(opening.mode == HandMode::posture);
    const float* expected = c.back.empty() ? f.open_rad : f.prepinch_rad;
    for (int j = 0; j < kHandJoints; ++j)
      CHECK(opening.target_rad[j] == doctest::Approx(expected[j]));
    REQUIRE(out.arm_count[kPinching] == 1);
    const ArmGoal& pin = out.arm[kPinching][0];
    if (c.back.empty()) {
      CHECK(pin.frame == ArmGoal::measured);  // straight up
      CHECK(pin.point_count == 1);
      continue;
    }
    REQUIRE(pin.frame == ArmGoal::sheet);
    CHECK(pin.kind == ArmGoal::retreat);
    const int n = static_cast<int>(c.back.size());
    REQUIRE(pin.point_count == n + 2);  // the via points, above_mm, above_via[0]
    for (int k = 0; k < n; ++k)
      for (int i = 0; i < 3; ++i)
        CHECK(pin.position_mm[k][i] ==
              doctest::Approx(f.via_mm[c.back[static_cast<std::size_t>(k)]][i]));
    CHECK(pin.orientation[0][0] == doctest::Approx(f.via_orientation[c.back[0]][0]));
    const double via[3] = {-95.0, -1.5, -300.0};
    for (int i = 0; i < 3; ++i) {
      CHECK(pin.position_mm[n][i] == doctest::Approx(f.grasp_above_mm[i]));
      CHECK(pin.position_mm[n + 1][i] == doctest::Approx(via[i]).epsilon(1e-4));
    }
    CHECK(std::fabs(pin.orientation[n + 1][1]) == doctest::Approx(0.85576).epsilon(1e-4));
  }
}
