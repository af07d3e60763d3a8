#include "plugins/fold_sequence/machine.h"

#include <cstring>

namespace crease::fold {
namespace {

void copy_text(char* dst, std::size_t n, const char* a, const char* b = nullptr) noexcept {
  std::size_t at = 0;
  for (const char* t : {a, b}) {
    if (t == nullptr) continue;
    while (*t != '\0' && at + 1 < n) dst[at++] = *t++;
  }
  dst[at] = '\0';
}

// "abort: <reason>" or "abort: <reason>: <detail>" (e.g. "abort: device_fault: contact_r
// unhealthy").
void abort_why(char* dst, std::size_t n, const char* reason, const char* detail) noexcept {
  copy_text(dst, n, "abort: ", reason);
  if (detail == nullptr) return;
  const std::size_t at = std::strlen(dst);
  copy_text(dst + at, n - at, ": ", detail);
}

S common_ancestor(S a, S b) noexcept {
  for (S x = a;; x = state_info(x).parent) {
    if (is_within(b, x)) return x;
    if (x == S::root) return S::root;
  }
}

}  // namespace

std::uint64_t spec_hash(const FoldSpec& f) noexcept {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a
  auto mix = [&h](const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  mix(f.name.data(), f.name.size());
  mix(&f.via_count, sizeof f.via_count);
  mix(f.via_mm, sizeof f.via_mm);
  mix(&f.pinching_side, sizeof f.pinching_side);  // the roles' sides: the memory's goal ids are per side
  return h;
}

Machine::Machine(const FoldSpec& spec) noexcept : spec_(spec) { m_.spec_hash = spec_hash(spec); }

bool Machine::restore(const Memory& saved) noexcept {
  if (saved.tag != Memory::kTag || saved.version != Memory::kVersion || saved.spec_hash != m_.spec_hash ||
      static_cast<int>(saved.leaf) >= kStateCount || !is_leaf(saved.leaf))
    return false;
  m_ = saved;
  return true;
}

SequenceStatus::Phase Machine::phase() const noexcept {
  if (m_.leaf == S::idle) return SequenceStatus::idle;
  if (m_.leaf == S::done) return SequenceStatus::done;
  if (m_.leaf == S::aborted || is_within(m_.leaf, S::abort)) return SequenceStatus::aborted;
  if (m_.paused || m_.gate_row >= 0) return SequenceStatus::paused;
  return SequenceStatus::running;
}

void Machine::fill_status(SequenceStatus& s, std::int64_t now_ns) const noexcept {
  s = SequenceStatus{};
  s.timestamp_ns = now_ns;
  s.state_since_ns = m_.leaf_since_ns;
  s.time_in_state_s = static_cast<double>(m_.elapsed_ns[static_cast<int>(m_.leaf)]) * 1e-9;
  s.transitions = m_.transitions;
  s.aborts = m_.aborts;
  s.state = static_cast<std::uint16_t>(m_.leaf);
  s.via = m_.via;
  s.phase = phase();
  s.step_mode = m_.step_mode;
  s.abort_reason = static_cast<std::uint8_t>(m_.abort_reason);
  write_path(m_.leaf, m_.via, s.path, sizeof s.path);
  const RowSpan rows = all_rows();
  if (m_.last_reason == Reason::operator_abort) {
    copy_text(s.why, sizeof s.why, "operator abort");
  } else if (m_.last_row >= 0 && m_.last_row < rows.end - rows.begin) {
    const Row& r = rows.begin[m_.last_row];
    if (r.ev == Ev::fault || r.from == S::fold)
      abort_why(s.why, sizeof s.why, reason_name(m_.last_reason), abort_detail_);
    else
      copy_text(s.why, sizeof s.why, r.why);
  } else if (m_.last_reason != Reason::none) {
    abort_why(s.why, sizeof s.why, reason_name(m_.last_reason), abort_detail_);
  }
  if (m_.start_pending && !is_within(m_.leaf, S::fold) && !is_within(m_.leaf, S::abort))
    copy_text(s.why, sizeof s.why, "start: waiting for the controllers and the sheet");
  copy_text(s.fold, sizeof s.fold, spec_.name.c_str());
}

void Machine::count_time(std::int64_t now_ns) noexcept {
  const std::int64_t dt = m_.last_ns == 0 || now_ns < m_.last_ns ? 0 : now_ns - m_.last_ns;
  m_.last_ns = now_ns;
  if (m_.paused || m_.gate_row >= 0) return;
  for (S x = m_.leaf; x != S::root; x = state_info(x).parent) m_.elapsed_ns[static_cast<int>(x)] += dt;
}

bool Machine::timed_out(S owner) const noexcept {
  // The owner or any active state below it past its own timeout (0: none).
  for (S x = m_.leaf;; x = state_info(x).parent) {
    const double t = spec_.timeout_s[static_cast<std::size_t>(x)];
    if (t > 0 && static_cast<double>(m_.elapsed_ns[static_cast<int>(x)]) > t * 1e9) return true;
    if (x == owner || x == S::root) return false;
  }
}

void Machine::go(S to, Reason r, int row, const Sensing& in, Outbox& out) noexcept {
  const S from = m_.leaf;
  const bool self = to == from;
  const S lca = self ? state_info(from).parent : common_ancestor(from, to);
  for (S x = from; x != lca; x = state_info(x).parent) exit(x, in, out);
  S chain[8];
  int k = 0;
  for (S x = to; x != lca && k < 8; x = state_info(x).parent) chain[k++] = x;
  m_.last_reason = r;
  m_.last_row = static_cast<std::int16_t>(row);
  m_.gate_row = -1;
  m_.paused = 0;
  ++m_.transitions;
  if (r != Reason::condition && r != Reason::started && is_within(to, S::abort) &&
      !is_within(from, S::abort)) {
    m_.abort_reason = r;
    abort_detail_ = row >= 0 && all_rows().begin[row].ev == Ev::fault ? detail_ : nullptr;
  }
  if (is_within(to, S::abort) && !is_within(from, S::abort)) {
    m_.aborted_from = from;
    const ArmMotionStatus* a = in.arm[kPinching];  // how far the pinching arm's goal had come
    m_.aborted_segment =
        a != nullptr && a->goal_id == m_.arm_id[kPinching] ? a->segment : Memory::kNoSegment;
  }
  m_.self_entry = self ? 1 : 0;
  S x = to;
  for (int i = k - 1; i >= 0; --i) {
    m_.leaf = chain[i];
    enter(chain[i], in, out);
  }
  while (!is_leaf(x)) {
    x = state_info(x).initial;
    m_.leaf = x;
    enter(x, in, out);
  }
  m_.leaf = x;
  m_.self_entry = 0;
  m_.leaf_since_ns = in.now_ns;
}

void Machine::apply_command(const Sensing& in, Outbox& out) noexcept {
  const Command c = command_;
  command_ = Command::none;
  const bool folding = is_within(m_.leaf, S::fold);
  switch (c) {
    case Command::none: break;
    case Command::start:
      if (!folding && !is_within(m_.leaf, S::abort)) m_.start_pending = 1;
      break;
    case Command::pause:
      if (folding && !m_.paused) {
        m_.paused = 1;
        stop_for_pause(out);
      }
      break;
    case Command::step:
    case Command::resume: {
      m_.step_mode = c == Command::step ? 1 : 0;
      if (!folding) {
        if (c == Command::step && !is_within(m_.leaf, S::abort)) m_.start_pending = 1;  // start, then pause
        break;
      }
      if (m_.gate_row >= 0) {
        const Row& r = all_rows().begin[m_.gate_row];
        go(r.to, r.reason, m_.gate_row, in, out);
      } else if (m_.paused) {
        m_.paused = 0;
        exit(m_.leaf, in, out);
        m_.self_entry = 0;
        enter(m_.leaf, in, out);  // the state's commands again, from where the robot stopped
      }
      for (int s = 0; s < 2; ++s) {  // the hands a pause held press again, unless the state sent them a goal
        if (m_.held_by_pause[s] && out.hand_count[s] == 0 && is_within(m_.leaf, S::fold))
          hand_force(s, m_.force_fingers[s], m_.force_n[s], in, out);
        m_.held_by_pause[s] = 0;
      }
      break;
    }
    case Command::abort:
      if (folding) go(S::abort, Reason::operator_abort, -1, in, out);
      break;
  }
}

void Machine::step(const Sensing& in, Outbox& out) noexcept {
  out.clear();
  count_time(in.now_ns);
  if (command_ != Command::none) {
    apply_command(in, out);
    if (out.arm_count[0] + out.arm_count[1] + out.hand_count[0] + out.hand_count[1] > 0 || out.has_crease ||
        out.has_memorize)
      return;  // one set of commands per cycle
  }
  const bool folding = is_within(m_.leaf, S::fold);
  detected_ = Reason::none;
  detail_ = nullptr;
  if (folding) {
    detected_ = external_fault_ != Reason::none ? external_fault_ : fault(in);
    external_fault_ = Reason::none;
  } else {
    external_fault_ = Reason::none;
  }
  report_retreat(in, out);
  const bool held = m_.paused || m_.gate_row >= 0;
  const RowSpan rows = all_rows();
  // Two passes: a fault's rows (fold's) first, so that a fault preempts any success of the same
  // cycle; then every other row, the innermost state's first. A paused machine: faults only.
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1 && held) return;
    for (S owner = m_.leaf; owner != S::root; owner = state_info(owner).parent) {
      const RowSpan own = rows_of(owner);
      for (const Row* r = own.begin; r != own.end; ++r) {
        if ((r->ev == Ev::fault) != (pass == 0)) continue;
        if (!holds(r->ev, owner, in) || !passes(r->guard, in)) continue;
        const int index = static_cast<int>(r - rows.begin);
        const Reason why = r->ev == Ev::fault ? detected_ : r->reason;
        if (m_.step_mode && !is_within(r->to, S::abort) && r->to != S::aborted && r->ev != Ev::start) {
          m_.gate_row = static_cast<std::int16_t>(index);  // held until `step` or `resume`
          return;
        }
        go(r->to, why, index, in, out);
        m_.start_pending = 0;
        return;
      }
    }
  }
  retry_retreat(in, out);  // no transition this cycle
}

}  // namespace crease::fold
