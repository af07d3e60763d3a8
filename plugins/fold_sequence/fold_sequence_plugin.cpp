#include "plugins/fold_sequence/fold_sequence_plugin.h"

#include <cmath>
#include <cstring>

namespace crease::fold {

void FoldSequencePlugin::configure(const Params& p, PortBinder& ports) {
  spec_ = load_fold_file(p.get_path("fold"));
  auto_start_ = p.get<bool>("auto_start", false);
  const double poll_ms = p.get_in_range<double>("sheet_poll_ms", 200.0, 0.0, 1000.0);
  if (poll_ms * 1e-3 >= spec_.sheet_max_age_s)
    p.fail("sheet_poll_ms", "must be below the fold's sensing.sheet_max_age_s (" +
                                format_number(spec_.sheet_max_age_s * 1e3) + " ms), else a live sheet reads as stale");
  sheet_poll_ns_ = static_cast<std::int64_t>(poll_ms * 1e6);
  machine_ = std::make_unique<Machine>(spec_);
  outbox_ = std::make_unique<Outbox>();
  ports.tunable("command", &command_, 0.0, 5.0);
  // Role s (kFixing, kPinching) on the ports of its side.
  const char* side[2] = {"r", "l"};
  for (int s = 0; s < 2; ++s) {
    const std::string x = side[side_of_role(spec_, s)];
    arm_status_[s] = ports.latest_input<ArmMotionStatus>("arm_" + x + "_status");
    hand_status_[s] = ports.latest_input<HandControlStatus>("hand_" + x + "_status");
    contact_[s] = ports.latest_input<ContactState>("contact_" + x + "_state");
    arm_goal_[s] = ports.queue_output<ArmGoal>("arm_" + x + "_goal");
    hand_goal_[s] = ports.queue_output<HandGoal>("hand_" + x + "_goal", kHandGoalQueue);
  }
  sheet_ = ports.latest_input<SheetState>("sheet_state");
  keypoints_ = ports.latest_input<Keypoints>("keypoints");
  crease_ = ports.queue_output<SheetCreaseEvent>("sheet_crease");
  memorize_ = ports.queue_output<SheetMemorizeEvent>("sheet_memorize");
  status_ = ports.latest_output<SequenceStatus>("sequence_status", SequenceStatus{});
  target_value_ = std::make_unique<TargetPoints>();
  target_ = ports.latest_output<TargetPoints>("target_points", *target_value_);
  target_written_ns_ = 0;
  targets_on_ = 0;
}

void FoldSequencePlugin::activate() { started_ = false; }

std::string FoldSequencePlugin::validate_param(std::string_view key, double value) {
  if (key == "command" && value != std::floor(value))
    return "command: 1 start, 2 pause, 3 resume, 4 abort, 5 step (got " + format_number(value) + ")";
  return {};
}

Status FoldSequencePlugin::update(const Cycle& c) {
  if (auto_start_ && !started_) machine_->command(Command::start);
  started_ = true;
  if (command_ != 0) {
    machine_->command(static_cast<Command>(static_cast<int>(command_)));
    command_ = 0;
  }
  Sensing in;
  in.now_ns = c.time_ns;
  for (int s = 0; s < 2; ++s) {
    (void)arm_status_[s].poll();
    (void)hand_status_[s].poll();
    (void)contact_[s].poll();
    if (arm_status_[s].has_value()) in.arm[s] = &arm_status_[s].value();
    if (hand_status_[s].has_value()) in.hand[s] = &hand_status_[s].value();
    if (contact_[s].has_value()) in.contact[s] = &contact_[s].value();
  }
  // The sheet (164 kB a copy) only while folding (or waiting to start), and at most every sheet_poll_ms: a copy per
  // model frame would cost the control loop tens of microseconds on 60 cycles a second.
  const bool folding = is_within(machine_->memory().leaf, S::fold) || machine_->memory().start_pending;
  if (folding && (sheet_polled_ns_ == 0 || c.time_ns - sheet_polled_ns_ >= sheet_poll_ns_)) {
    (void)sheet_.poll();
    sheet_polled_ns_ = c.time_ns;
  }
  if (sheet_.has_value()) in.sheet = &sheet_.value();
  // The markers' key-points (16 kB) from the lay on, while the laid layer is judged by them.
  if (layer_laid(machine_->memory().leaf)) (void)keypoints_.poll();
  if (keypoints_.has_value()) in.keypoints = &keypoints_.value();

  Outbox& out = *outbox_;
  machine_->step(in, out);
  bool lost = out.overflow;
  for (int s = 0; s < 2; ++s) {
    for (int i = 0; i < out.arm_count[s]; ++i) lost |= !arm_goal_[s].try_push(out.arm[s][i]);
    for (int i = 0; i < out.hand_count[s]; ++i) lost |= !hand_goal_[s].try_push(out.hand[s][i]);
  }
  if (out.has_crease) lost |= !crease_.try_push(out.crease);
  if (out.has_memorize) lost |= !memorize_.try_push(out.memorize);
  if (lost) machine_->fail(Reason::command_lost);
  log_retreat(out);

  write_targets(in, c.time_ns);
  machine_->fill_status(status_value_, c.time_ns);
  status_.write(status_value_, c.time_ns);
  if (status_value_.transitions != logged_transitions_) {
    // Each transition on the report's timeline (the host records a mark as this instance's
    // event, at the time it was logged, and logs it): "fold/shift/contact: fixing arm contact stop".
    logged_transitions_ = status_value_.transitions;
    char text[96];
    std::size_t n = 0;
    const auto append = [&](const char* s, std::size_t max) {
      for (std::size_t i = 0; i < max && s[i] != '\0' && n + 1 < sizeof text; ++i) text[n++] = s[i];
    };
    append(status_value_.path, sizeof status_value_.path);
    append(": ", 2);
    append(status_value_.why, sizeof status_value_.why);
    text[n] = '\0';
    log_rt(rt::LogLevel::mark, text);
  }
  return status_value_.phase == SequenceStatus::aborted ? Status::degraded : Status::ok;
}

void FoldSequencePlugin::write_targets(const Sensing& in, std::int64_t now_ns) noexcept {
  double world[2][3], sheet[2][2];
  std::uint32_t n = 0;
  if (machine_->grasp_target(in, world[n], sheet[n])) ++n;
  if (machine_->press_target(in, world[n], sheet[n])) ++n;
  if (n == 0 && targets_on_ == 0) return;
  if (n == targets_on_ && now_ns - target_written_ns_ < kTargetPeriodNs) return;
  TargetPoints& t = *target_value_;
  t.timestamp_ns = now_ns;
  t.count = n;
  for (std::uint32_t k = 0; k < n; ++k) {
    for (int c = 0; c < 3; ++c) t.points[k].world_mm[c] = static_cast<float>(world[k][c]);
    for (int c = 0; c < 2; ++c) t.points[k].sheet_mm[c] = static_cast<float>(sheet[k][c]);
  }
  target_.write(t, now_ns);
  target_written_ns_ = now_ns;
  targets_on_ = n;
}

void FoldSequencePlugin::log_retreat(const Outbox& out) const noexcept {
  // What the abort's retreat did to an arm's goal this cycle, per role (its text by role: the
  // log takes no formatting in the loop).
  struct Line {
    bool happened;
    const char* text[2];  // kFixing, kPinching
    std::int64_t value;   // -1: none
  };
  for (int r = 0; r < 2; ++r) {
    const Line lines[] = {
        {out.retried[r] != Outbox::kNoRetry,
         {"retreat: the fixing arm's goal ended short (arm_motion reason), sent again",
          "retreat: the pinching arm's goal ended short (arm_motion reason), sent again"},
         out.retried[r]},
        {out.park_lift[r],
         {"retreat: the fixing arm's park, out of reach on a line: the hand lifted first "
          "(park_lift_mm)",
          "retreat: the pinching arm's park, out of reach on a line: the hand lifted first "
          "(park_lift_mm)"},
         -1},
        {out.joints_park[r],
         {"retreat: the fixing arm's park, out of reach on a line, sent in joint space",
          "retreat: the pinching arm's park, out of reach on a line, sent in joint space"},
         -1},
        {out.gave_up[r] != Outbox::kNoRetry,
         {"retreat: the fixing arm's goal ended short for good (arm_motion reason)",
          "retreat: the pinching arm's goal ended short for good (arm_motion reason)"},
         out.gave_up[r]},
    };
    for (const Line& l : lines) {
      if (!l.happened) continue;
      if (l.value >= 0)
        log_rt(rt::LogLevel::warn, l.text[r], l.value);
      else
        log_rt(rt::LogLevel::warn, l.text[r]);
    }
  }
}

std::size_t FoldSequencePlugin::save_state(std::span<std::byte> out) const noexcept {
  if (out.size() < sizeof(Memory)) return SIZE_MAX;
  std::memcpy(out.data(), &machine_->memory(), sizeof(Memory));
  return sizeof(Memory);
}

bool FoldSequencePlugin::load_state(std::span<const std::byte> in) noexcept {
  if (in.size() != sizeof(Memory)) return false;
  Memory m;
  std::memcpy(&m, in.data(), sizeof(Memory));
  if (!machine_->restore(m)) return false;
  logged_transitions_ = m.transitions;
  started_ = true;  // a swapped-in instance goes on; it does not start the fold again
  return true;
}

}  // namespace crease::fold
