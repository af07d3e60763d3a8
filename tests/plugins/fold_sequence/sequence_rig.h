// A rig for the fold_sequence plugin: the plugin on a PortRegistry of the test's own, and a
// scripted robot standing in for the controllers and the sheet model on the same ports
// (arm_motion's statuses, the force and contact controllers' statuses, the model's
// sheet_state). Each cycle: the robot answers the goals it took so far (as the controllers,
// ordered before the sequence, would in the loop), then the plugin's update, then the robot
// takes the goals the plugin pushed. Deterministic: time is the cycle count (1 ms a cycle).
#pragma once

#include <doctest/doctest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/params.h"
#include "core/port_binder.h"
#include "core/port_registry.h"
#include "core/port_types/sequence_status.h"
#include "plugins/fold_sequence/fold_sequence_plugin.h"
#include "plugins/fold_sequence/sheet_geometry.h"
#include "rt/alloc_guard.h"

namespace rig {

using namespace crease;
using crease::fold::FoldSequencePlugin;

// The rig's sides: its ports in the plugin's order (arm_r_..., arm_l_...), whichever role each has.
inline constexpr int kRight = 0;
inline constexpr int kLeft = 1;

inline std::string fold_file(const char* name) { return std::string(CREASE_SOURCE_DIR) + "/config/folds/" + name; }

// A fold file's text, edited, written to a temporary file of its own (NAME, this process's pid
// appended): its path.
inline std::string read_fold_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}
inline void replace_once(std::string& text, const std::string& from, const std::string& to) {
  const std::size_t k = text.find(from);
  REQUIRE_MESSAGE(k != std::string::npos, "the fold file no longer has '" << from << "'");
  text.replace(k, from.size(), to);
}
inline std::string write_fold_text(const std::string& text, const std::string& name) {
  const std::string out =
      (std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".yaml"))
          .string();
  std::ofstream(out) << text;
  return out;
}

// The shipped half fold with its fixing hand shifting the sheet (shift.hand: fixing, pressing where
// it then fixates): the machine's one-hand shift, which most tests here walk. The shipped file
// (the pinching hand shifts, then lets go; the fixing hand comes down) has its own test.
inline std::string half_fixing_shift() {
  static const std::string path = [] {
    std::string s = read_fold_text(fold_file("half.yaml"));
    replace_once(s, "  hand: pinching\n", "  hand: fixing\n");
    replace_once(s, "  at_mm: [105, 88.5]", "  at_mm: [165, 88.5]");
    const std::size_t f0 = s.find("  fixate: {"),
                      f1 = s.find("}\n", f0);  // grasp.fixate: the shift's contact instead
    REQUIRE_MESSAGE((f0 != std::string::npos && f1 != std::string::npos),
                    "half.yaml no longer has grasp.fixate");
    s.erase(f0, f1 + 2 - f0);
    return write_fold_text(s, "crease_half_fixing_shift");
  }();
  return path;
}

// One goal the robot took, in order.
struct Sent {
  long cycle = 0;
  int side = 0;
  enum Kind { arm, hand, crease, memorize } kind = arm;
  ArmGoal arm_goal{};
  HandGoal hand_goal{};
  SheetCreaseEvent crease_event{};
};

class Rig {
 public:
  // TURNED: the sheet as the simulated robot lays it for the half fold (config/sim.yaml), 25 mm
  // and 21.5 mm short of where its shift puts it; else as it lay before, corner (0, 0) at
  // (-105, 148.5), u along +x.
  explicit Rig(const std::string& fold = half_fixing_shift(), bool turned = true)
      : fold_(fold),
        sheet_(std::make_unique<SheetState>()),
        keypoints_(std::make_unique<Keypoints>()) {
    plugin_ = make_plugin();
    for (int s = 0; s < 2; ++s) {
      const std::string x = s == 0 ? "r" : "l";
      arm_out_[s] = rig_ports_.latest_output<ArmMotionStatus>("arm_" + x + "_status", ArmMotionStatus{});
      hand_out_[s] = rig_ports_.latest_output<HandControlStatus>("hand_" + x + "_status", HandControlStatus{});
      contact_out_[s] = rig_ports_.latest_output<ContactState>("contact_" + x + "_state", ContactState{});
      arm_in_[s] = rig_ports_.queue_input<ArmGoal>("arm_" + x + "_goal");
      hand_in_[s] = rig_ports_.queue_input<HandGoal>("hand_" + x + "_goal", FoldSequencePlugin::kHandGoalQueue);  // as force_controller
    }
    crease_in_ = rig_ports_.queue_input<SheetCreaseEvent>("sheet_crease");
    memorize_in_ = rig_ports_.queue_input<SheetMemorizeEvent>("sheet_memorize");
    sheet_out_ = rig_ports_.latest_output<SheetState>("sheet_state", *sheet_);
    keypoints_out_ = rig_ports_.latest_output<Keypoints>("keypoints", *keypoints_);
    status_in_ = rig_ports_.latest_input<SequenceStatus>("sequence_status");
    if (turned) {
      place_sheet(80, -170, true);
    } else {
      place_sheet(-105, 148.5, false);
    }
    for (int s = 0; s < 2; ++s) {
      contact_[s].armed = 1;
      contact_[s].healthy = 1;
    }
  }

  // A new instance of the plugin on the same ports (a hot-swap's new version).
  std::unique_ptr<FoldSequencePlugin> make_plugin() {
    auto p = std::make_unique<FoldSequencePlugin>();
    binders_.push_back(std::make_unique<PortBinder>(registry_, "fold", std::map<std::string, std::string>{}, &flags_, nullptr));
    const Params params(YAML::Load("{fold: " + fold_ + "}"), "test.yaml", "fold.params");
    ConfigureContext ctx{&params, binders_.back().get()};
    p->attach_host(ctx);
    p->configure(params, *binders_.back());
    p->activate();
    return p;
  }
  void replace_plugin(std::unique_ptr<FoldSequencePlugin> p) { plugin_ = std::move(p); }
  FoldSequencePlugin& plugin() { return *plugin_; }

  // What the host does for `param set fold command N`: writes the tunable between two updates.
  void command(fold::Command c) {
    for (Tunable& t : binders_.back()->tunables())
      if (t.key == "command") *t.target = static_cast<double>(c);
  }

  // The flat sheet, 3 x 3 nodes, corner (0, 0) at world (x0, y0), u along +x, v along -y
  // (TURNED: u along -x, v along +y), then turned YAW rad about the vertical through that corner.
  void place_sheet(double x0, double y0, bool turned, double yaw = 0.0) {
    const double sign = turned ? -1.0 : 1.0;
    const double c = std::cos(yaw), sn = std::sin(yaw);
    SheetState& s = *sheet_;
    s.nodes_u = 3;
    s.nodes_v = 3;
    s.width_mm = 210;
    s.height_mm = 297;
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        float* p = s.position_mm[j * 3 + i];
        const double dx = sign * 105.0 * i, dy = -sign * 148.5 * j;
        p[0] = static_cast<float>(x0 + c * dx - sn * dy);
        p[1] = static_cast<float>(y0 + sn * dx + c * dy);
        p[2] = 0;
        s.normal[j * 3 + i][2] = -1;
        for (int c = 0; c < 3; ++c) flat_[j * 3 + i][c] = p[c];
      }
  }
  // Vision sees N markers' key-points (printed face) at sheet point (u, v) mm from now on, a
  // frame every 66 cycles (15 Hz), stamped as taken; N 0: none.
  void show_markers(std::uint32_t n, double u, double v) {
    keypoints_->count = n;
    for (std::uint32_t i = 0; i < n; ++i) {
      Keypoint& k = keypoints_->points[i];
      k = Keypoint{};
      k.sheet_mm[0] = static_cast<float>(u + 0.1 * i);
      k.sheet_mm[1] = static_cast<float>(v);
    }
    keypoints_live_ = true;
  }
  // Node (i, j) of the tracked sheet to world (x, y, z) mm (a shape the model took).
  void set_node(int i, int j, double x, double y, double z) {
    float* p = sheet_->position_mm[j * sheet_->nodes_u + i];
    p[0] = static_cast<float>(x);
    p[1] = static_cast<float>(y);
    p[2] = static_cast<float>(z);
  }
  // The laid layer springs back: the node the pinch carried returns to where it lay flat (the
  // tracked sheet unfolded).
  void spring_back() {
    REQUIRE(carried_ >= 0);
    for (int c = 0; c < 3; ++c) sheet_->position_mm[carried_][c] = flat_[carried_][c];
    carried_new_ = true;
  }

  // One control cycle.
  void cycle() {
    ++n_;
    now_ = 1'000'000'000LL + n_ * 1'000'000LL;
    answer();
    Cycle c{};
    c.time_ns = now_;
    c.index = static_cast<std::uint64_t>(n_);
    {
      rt::ScopedRtMark rt_mark;
      const std::uint64_t a0 = rt::rt_allocation_count();
      status_ = plugin_->update(c);
      allocations_ += rt::rt_allocation_count() - a0;
    }
    take();
    (void)status_in_.poll();
    const SequenceStatus& st = status_in_.value();
    if (paths_.empty() || paths_.back() != st.path) paths_.push_back(st.path);
  }
  // Runs cycles until pred() holds (true) or max cycles passed (false).
  bool run_until(const std::function<bool()>& pred, long max = 200000) {
    for (long i = 0; i < max; ++i) {
      if (pred()) return true;
      cycle();
    }
    return pred();
  }
  bool run_to(const std::string& path, long max = 200000) {
    return run_until([&] { return status().path == path; }, max);
  }
  void run(long cycles) {
    for (long i = 0; i < cycles; ++i) cycle();
  }

  const SequenceStatus& status() const { return status_in_.value(); }
  // The tracked sheet drifting (the model's estimate, not the world): every node moved by
  // (dx, dy) mm in the world.
  void drift(double dx, double dy) {
    SheetState& sh = *sheet_;
    for (int k = 0; k < sh.nodes_u * sh.nodes_v; ++k) {
      sh.position_mm[k][0] += static_cast<float>(dx);
      sh.position_mm[k][1] += static_cast<float>(dy);
    }
  }
  // The tracked sheet the rig publishes.
  const SheetState& sheet() const { return *sheet_; }
  const std::vector<std::string>& paths() const { return paths_; }
  const std::vector<Sent>& sent() const { return sent_; }
  std::uint64_t allocations() const { return allocations_; }
  long cycles() const { return n_; }
  Status last_update_status() const { return status_; }

  // The last goal sent to side's hand / arm (nullptr when none).
  const Sent* last(int side, Sent::Kind kind) const {
    for (auto it = sent_.rbegin(); it != sent_.rend(); ++it)
      if (it->kind == kind && it->side == side) return &*it;
    return nullptr;
  }
  std::vector<const Sent*> all(int side, Sent::Kind kind, long from_cycle = 0) const {
    std::vector<const Sent*> out;
    for (const Sent& s : sent_)
      if (s.kind == kind && s.side == side && s.cycle >= from_cycle) out.push_back(&s);
    return out;
  }

  // The rig's own end of the ports (a port the tests read), and the fold file it runs.
  PortBinder& ports() { return rig_ports_; }
  [[nodiscard]] const std::string& fold_path() const { return fold_; }

  // --- the scripted robot's knobs ---
  int move_cycles = 20;       // a motion runs this long, then reaches (or stops on contact)
  int settle_cycles = 15;     // a force goal settles after this
  int posture_cycles = 10;    // a posture ramps this long
  std::uint32_t observations = 12;  // per sheet_state
  bool sheet_live = true;     // false: sheet_state no longer written (stale)
  bool pinch_carries = true;  // false: the pinch's goals leave the sheet where it lies (carry())
  // In the shift, a hand pressing (force mode) drags the tracked sheet by this share of each of its
  // arm's moves (1: with the finger; 0.5: half the way, the finger slipping over the sheet).
  double shift_drag = 1.0;
  // Per arm goal (side, goal, index of the side's move goals): refuse as unreachable / never end.
  std::function<bool(int, const ArmGoal&, int)> unreachable = [](int, const ArmGoal&, int) { return false; };
  std::function<bool(int, const ArmGoal&, int)> stalls = [](int, const ArmGoal&, int) { return false; };
  // Per arm move goal: refused at once with this reason (as arm_motion's refuse), or run half
  // its cycles and then aborted with it (an arm_state gone stale, say); none: as usual.
  std::function<ArmMotionReason(int, const ArmGoal&, int)> refuse_as = [](int, const ArmGoal&, int) {
    return ArmMotionReason::none;
  };
  std::function<ArmMotionReason(int, const ArmGoal&, int)> abort_as = [](int, const ArmGoal&, int) {
    return ArmMotionReason::none;
  };
  HandInhibit inhibit[2] = {HandInhibit::none, HandInhibit::none};
  bool arm_fault[2] = {false, false};  // the running motion aborts with arm_fault
  bool miss_contact[2] = {false, false};  // a contact descent reaches its depth, nothing touched
  bool refuse_hand_goals[2] = {false, false};  // every hand goal refused (inputs bad)
  // The pinch posture ends with th and ff squeezing (0.5 N each); false: the pads close on
  // nothing, though contact_state still names both (as a lagging ramp makes it do).
  bool pinch_feels = true;
  // What each arm's status says of its tool's measured position (world mm).
  bool tool_measured = true;
  double tool_at[2][3] = {{10, 20, 30}, {-40, 50, 60}};

 private:
  struct Arm {
    ArmMotionStatus st{};
    ArmGoal goal{};
    ArmMotionReason abort_as = ArmMotionReason::none;
    int left = 0;  // cycles to go
    bool stall = false;
    int moves = 0;
  };
  struct Hand {
    HandControlStatus st{};
    int left = 0;
    bool pinch = false;
  };

  // A sheet-frame goal reached by a closed pinch takes the pinched node along (the node
  // nearest the goal's u, v when the pinch first carries): the tracked grasp point follows the
  // pinch as the model would (pinch_carries false: it stays, as after a lost pinch).
  void carry(int s, const ArmGoal& g) {
    if (!pinch_carries || !hands_[s].pinch || g.point_count == 0) return;
    const double* p = g.position_mm[g.point_count - 1];
    if (g.frame == ArmGoal::world && carried_ >= 0) {  // a goal in the frame held from the bend
      for (int c = 0; c < 3; ++c) sheet_->position_mm[carried_][c] = static_cast<float>(p[c]);
      carried_new_ = true;
      return;
    }
    if (g.frame != ArmGoal::sheet) return;
    crease::fold::SheetFrame f;
    if (!crease::fold::sheet_frame(*sheet_, f)) return;
    if (carried_ < 0)
      carried_ = static_cast<int>(std::lround(std::clamp(p[1] / 148.5, 0.0, 2.0))) * 3 +
                 static_cast<int>(std::lround(std::clamp(p[0] / 105.0, 0.0, 2.0)));
    double w[3];
    crease::fold::sheet_to_world(f, p, w);
    for (int c = 0; c < 3; ++c) sheet_->position_mm[carried_][c] = static_cast<float>(w[c]);
    carried_new_ =
        true;  // published this cycle: the rig's motions are shorter than the model's period
  }

  // Where side S's tool is put by goal G in the world (x, y; the tool's last known place for
  // a measured goal's offset); false for a goal that says nothing of it.
  bool goal_world_xy(int s, const ArmGoal& g, double out[2]) const {
    if (g.point_count == 0) return false;
    const double* p = g.position_mm[g.point_count - 1];
    if (g.frame == ArmGoal::measured) {
      if (!tool_known_[s]) return false;
      out[0] = tool_xy_[s][0] + p[0];
      out[1] = tool_xy_[s][1] + p[1];
      return true;
    }
    double w[3] = {p[0], p[1], p[2]};
    if (g.frame == ArmGoal::sheet) {
      crease::fold::SheetFrame f;
      if (!crease::fold::sheet_frame(*sheet_, f)) return false;
      crease::fold::sheet_to_world(f, p, w);
    }
    out[0] = w[0];
    out[1] = w[1];
    return true;
  }
  // Goal G of side S ended where it aimed: in the shift, a pressing hand drags the sheet
  // (shift_drag of the move); the tool's place is remembered for the next measured goal.
  void tool_arrived(int s, const ArmGoal& g) {
    double xy[2];
    if (!goal_world_xy(s, g, xy)) return;
    const bool pressing = hands_[s].st.mode == HandMode::force &&
                          std::string_view(status().path).starts_with("fold/shift/");
    if (pressing && tool_known_[s]) {
      const double dx = shift_drag * (xy[0] - tool_xy_[s][0]),
                   dy = shift_drag * (xy[1] - tool_xy_[s][1]);
      drift(dx, dy);
      for (auto& q : flat_) {
        q[0] += static_cast<float>(dx);
        q[1] += static_cast<float>(dy);
      }
      carried_new_ = true;
    }
    tool_xy_[s][0] = xy[0];
    tool_xy_[s][1] = xy[1];
    tool_known_[s] = true;
  }

  void answer() {
    for (int s = 0; s < 2; ++s) {
      Arm& a = arms_[s];
      if (a.st.state == ArmMotionStatus::running) {
        if (arm_fault[s]) {
          a.st.state = ArmMotionStatus::aborted;
          a.st.reason = static_cast<std::uint8_t>(ArmMotionReason::arm_fault);
        } else if (a.abort_as != ArmMotionReason::none && a.left <= move_cycles / 2) {
          a.st.state = ArmMotionStatus::aborted;
          a.st.reason = static_cast<std::uint8_t>(a.abort_as);
        } else if (!a.stall && --a.left <= 0) {
          if (a.goal.stop_on == ArmGoal::contact_onset && !miss_contact[s]) {
            tool_arrived(s,
                         a.goal);  // (near enough: the rig's contacts are where the descent aims)
            a.st.state = ArmMotionStatus::stopped_on_contact;
            contact_[s].in_contact = 1;
            contact_[s].fingers = a.goal.stop_fingers;
            ++contact_[s].onsets;
          } else {
            a.st.state = ArmMotionStatus::reached;
            tool_arrived(s, a.goal);
            carry(s, a.goal);
          }
        }
      }
      Hand& h = hands_[s];
      if (inhibit[s] != h.st.inhibit && inhibit[s] != HandInhibit::none) ++h.st.inhibits;  // as force_controller
      h.st.inhibit = inhibit[s];
      h.st.commanding = 1;
      if (h.left > 0 && --h.left == 0) {
        if (h.st.mode == HandMode::force) h.st.settled = 1;
        if (h.st.mode == HandMode::posture) {
          h.st.max_step_rad = 0;
          if (h.pinch) {
            contact_[s].in_contact = 1;
            contact_[s].fingers = 0x11;
            if (pinch_feels) h.st.force_n[0] = h.st.force_n[4] = 0.5f;  // th and ff squeeze the corner
          } else {
            for (float& f : h.st.force_n) f = 0;
            contact_[s].in_contact = 0;
            contact_[s].fingers = 0;
          }
        }
      }
      a.st.timestamp_ns = h.st.timestamp_ns = contact_[s].timestamp_ns = now_;
      a.st.tool = a.goal.tool;  // as arm_motion: the last goal's tool, where the readings put it
      a.st.tool_measured = tool_measured ? 1 : 0;
      for (int c = 0; c < 3; ++c) a.st.tool_mm[c] = static_cast<float>(tool_at[s][c]);
      arm_out_[s].write(a.st, now_);
      hand_out_[s].write(h.st, now_);
      contact_out_[s].write(contact_[s], now_);
    }
    if (sheet_live && (n_ % 16 == 0 || carried_new_)) {  // the model's 60 Hz, about
      carried_new_ = false;
      sheet_->timestamp_ns = now_;
      ++sheet_->step;
      sheet_->observations = observations;
      sheet_out_.write(*sheet_, now_);
    }
    if (keypoints_live_ && n_ % 66 == 0) {
      keypoints_->timestamp_ns = now_;
      ++keypoints_->frame;
      keypoints_out_.write(*keypoints_, now_);
    }
  }

  void take() {
    for (int s = 0; s < 2; ++s) {
      ArmGoal g;
      while (arm_in_[s].try_pop(g)) {
        Sent x;
        x.cycle = n_;
        x.side = s;
        x.kind = Sent::arm;
        x.arm_goal = g;
        sent_.push_back(x);
        Arm& a = arms_[s];
        if (g.kind == ArmGoal::stop) {
          if (a.st.state == ArmMotionStatus::running) {
            a.st.state = ArmMotionStatus::aborted;
            a.st.reason = static_cast<std::uint8_t>(ArmMotionReason::stopped);
          }
          continue;
        }
        const int index = a.moves++;
        if (unreachable(s, g, index)) {
          a.st.last_refused_id = g.id;
          a.st.last_refusal = static_cast<std::uint8_t>(ArmMotionReason::unreachable);
          a.st.goal_id = g.id;
          a.st.state = ArmMotionStatus::unreachable;
          a.st.reason = static_cast<std::uint8_t>(ArmMotionReason::unreachable);
          continue;
        }
        if (const ArmMotionReason why = refuse_as(s, g, index); why != ArmMotionReason::none) {
          a.st.last_refused_id = g.id;
          a.st.last_refusal = static_cast<std::uint8_t>(why);
          if (a.st.state != ArmMotionStatus::running) {
            a.st.goal_id = g.id;
            a.st.state = ArmMotionStatus::refused;
            a.st.reason = static_cast<std::uint8_t>(why);
          }
          continue;
        }
        a.goal = g;
        a.abort_as = abort_as(s, g, index);
        a.st.goal_id = g.id;
        a.st.state = ArmMotionStatus::running;
        a.st.reason = 0;
        a.left = move_cycles;
        a.stall = stalls(s, g, index);
        const bool up =
            (g.frame == ArmGoal::sheet && g.position_mm[0][2] < -1) ||
            (g.frame != ArmGoal::sheet && g.position_mm[0][2] > 1);  // world: the table at 0
        if (g.stop_on == ArmGoal::stop_none && up) {
          contact_[s].in_contact = 0;  // lifting off
          contact_[s].fingers = 0;
        }
      }
      HandGoal hg;
      while (hand_in_[s].try_pop(hg)) {
        Sent x;
        x.cycle = n_;
        x.side = s;
        x.kind = Sent::hand;
        x.hand_goal = hg;
        sent_.push_back(x);
        Hand& h = hands_[s];
        if (refuse_hand_goals[s]) {  // as force_controller with bad inputs: refused, counted
          ++h.st.goals_refused;
          h.st.last_refusal = static_cast<std::uint8_t>(GoalRefusal::inputs_bad);
          continue;
        }
        h.st.goal_id = hg.id;
        h.st.mode = hg.mode;
        ++h.st.goals_accepted;
        h.st.settled = 0;
        h.st.max_step_rad = 0;
        h.left = 0;
        if (hg.mode == HandMode::force) h.left = settle_cycles;
        if (hg.mode == HandMode::posture) {
          h.left = posture_cycles;
          h.st.max_step_rad = 0.001f;
          h.pinch = hg.target_rad[3] > 0.3f && hg.target_rad[16] > 0.3f;
        }
      }
    }
    SheetCreaseEvent ce;
    while (crease_in_.try_pop(ce)) {
      Sent x;
      x.cycle = n_;
      x.kind = Sent::crease;
      x.crease_event = ce;
      sent_.push_back(x);
      const std::uint32_t k = sheet_->crease_count++;
      for (int c = 0; c < 2; ++c) {
        sheet_->crease_mm[k][c] = ce.a_mm[c];
        sheet_->crease_mm[k][2 + c] = ce.b_mm[c];
      }
    }
    SheetMemorizeEvent me;
    while (memorize_in_.try_pop(me)) {
      Sent x;
      x.cycle = n_;
      x.kind = Sent::memorize;
      sent_.push_back(x);
    }
  }

  std::string fold_;
  PortRegistry registry_;
  detail::OutputFlags flags_;
  std::vector<std::unique_ptr<PortBinder>> binders_;
  PortBinder rig_ports_{registry_, "rig", {}, &flags_, nullptr};
  std::unique_ptr<FoldSequencePlugin> plugin_;
  std::unique_ptr<SheetState> sheet_;
  std::unique_ptr<Keypoints> keypoints_;  // the frame vision sends from show_markers on
  bool keypoints_live_ = false;
  int carried_ = -1;  // the node the pinch carries (carry()); -1: none yet
  std::array<std::array<float, 3>, 9> flat_{};  // where place_sheet laid each node
  bool carried_new_ = false;
  double tool_xy_[2][2] = {};  // each tool's last known place (world x, y): tool_arrived()
  bool tool_known_[2] = {false, false};
  LatestOutput<ArmMotionStatus> arm_out_[2];
  LatestOutput<HandControlStatus> hand_out_[2];
  LatestOutput<ContactState> contact_out_[2];
  QueueInput<ArmGoal> arm_in_[2];
  QueueInput<HandGoal> hand_in_[2];
  QueueInput<SheetCreaseEvent> crease_in_;
  QueueInput<SheetMemorizeEvent> memorize_in_;
  LatestOutput<SheetState> sheet_out_;
  LatestOutput<Keypoints> keypoints_out_;
  LatestInput<SequenceStatus> status_in_;
  Arm arms_[2];
  Hand hands_[2];
  ContactState contact_[2]{};
  long n_ = 0;
  std::int64_t now_ = 0;
  Status status_ = Status::ok;
  std::uint64_t allocations_ = 0;
  std::vector<std::string> paths_;
  std::vector<Sent> sent_;
};

}  // namespace rig
