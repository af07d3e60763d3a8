#include "plugins/fold_sequence/graph.h"

#include <sstream>

#include "core/params.h"
#include "plugins/fold_sequence/fold_spec.h"
#include "plugins/fold_sequence/states.h"

namespace crease::fold {
namespace {

const char* event_name(Ev e) {
  switch (e) {
    case Ev::start: return "start";
    case Ev::timeout: return "timeout";
    case Ev::fault: return "fault";
    case Ev::arm_fix_reached: return "fixing arm reached";
    case Ev::arm_pin_reached: return "pinching arm reached";
    case Ev::arms_reached: return "arms reached";
    case Ev::arm_fix_contact: return "fixing arm contact stop";
    case Ev::arm_pin_contact: return "pinching arm contact stop";
    case Ev::arm_fix_missed: return "fixing arm at depth, no contact";
    case Ev::arm_pin_missed: return "pinching arm at depth, no contact";
    case Ev::hand_fix_settled: return "fixing hand settled";
    case Ev::hand_pin_settled: return "pinching hand settled";
    case Ev::hand_fix_posed: return "fixing hand posed";
    case Ev::hand_pin_posed: return "pinching hand posed";
    case Ev::hands_posed: return "hands posed";
    case Ev::pinched: return "pinched";
    case Ev::arm_shift_reached:
      return "shifting arm reached";
    case Ev::arm_shift_contact:
      return "shifting arm contact stop";
    case Ev::arm_shift_missed:
      return "shifting arm at depth, no contact";
    case Ev::hand_shift_settled:
      return "shifting hand settled";
    case Ev::crease_acked: return "crease in model";
    case Ev::sheet_settled:
      return "sheet settled";
    case Ev::memorized: return "model memorized";
    case Ev::stopped: return "stopped";
    case Ev::arms_done: return "arms done";
    case Ev::always: return "always";
  }
  return "?";
}

const char* guard_name(Guard g) {
  switch (g) {
    case Guard::none: return "";
    case Guard::ready: return "controllers, sheet ready";
    case Guard::slide_needed: return "slide needed";
    case Guard::slide_too_long: return "slide too long";
    case Guard::slide_again:
      return "corner short, slides left";
    case Guard::shifted_by_fixing:
      return "corner in reach, fixing hand shifted";
    case Guard::shifted_by_pinching:
      return "corner in reach, pinching hand shifted";
    case Guard::shift_armed:
      return "shifting contact armed";
    case Guard::fixing_armed: return "fixing contact armed";
    case Guard::pinching_armed: return "pinching contact armed";
    case Guard::more_via: return "more via";
    case Guard::last_via: return "last via";
  }
  return "?";
}

std::string id(S s) {
  char buf[96];
  write_path(s, -1, buf, sizeof buf);
  std::string out = "s_";
  for (const char* c = buf; *c; ++c) out += (*c == '/') ? '_' : *c;
  return out;
}

// A superstate's edges start or end at an invisible anchor inside its cluster.
std::string node_of(S s) { return is_leaf(s) ? id(s) : id(s) + "_anchor"; }

void cluster(std::ostringstream& o, S s, const FoldSpec* f, int indent) {
  const std::string pad(static_cast<std::size_t>(indent) * 2, ' ');
  const StateInfo& info = state_info(s);
  std::string label = info.name;
  if (f != nullptr) {
    const double t = f->timeout_s[static_cast<std::size_t>(s)];
    if (s == S::follow_via) label += "[0.." + std::to_string(f->via_count - 1) + "]";
    if (t > 0) label += "\\n" + format_number(t) + " s";
  }
  if (is_leaf(s)) {
    o << pad << id(s) << " [label=\"" << label << "\"];\n";
    return;
  }
  o << pad << "subgraph cluster_" << id(s) << " {\n" << pad << "  label=\"" << label << "\";\n";
  o << pad << "  " << node_of(s) << " [shape=point, style=invis];\n";
  for (int i = 0; i < kStateCount; ++i) {
    const S c = static_cast<S>(i);
    if (c != S::root && state_info(c).parent == s) cluster(o, c, f, indent + 1);
  }
  o << pad << "}\n";
}

}  // namespace

std::string graphviz(const FoldSpec* fold) {
  std::ostringstream o;
  o << "digraph fold_sequence {\n  compound=true;\n  rankdir=LR;\n  node [shape=box, style=rounded];\n";
  if (fold != nullptr) o << "  label=\"fold: " << fold->name << "\";\n";
  for (int i = 1; i < kStateCount; ++i) {
    const S s = static_cast<S>(i);
    if (state_info(s).parent == S::root) cluster(o, s, fold, 1);
  }
  // Initial children: a dashed edge from the superstate's anchor.
  for (int i = 1; i < kStateCount; ++i) {
    const S s = static_cast<S>(i);
    if (!is_leaf(s)) o << "  " << node_of(s) << " -> " << node_of(state_info(s).initial) << " [style=dashed];\n";
  }
  const RowSpan rows = all_rows();
  for (const Row* r = rows.begin; r != rows.end; ++r) {
    std::string label = event_name(r->ev);
    if (r->guard != Guard::none) label += std::string(" [") + guard_name(r->guard) + "]";
    o << "  " << node_of(r->from) << " -> " << node_of(r->to) << " [label=\"" << label << "\"";
    if (!is_leaf(r->from)) o << ", ltail=cluster_" << id(r->from);
    if (!is_leaf(r->to)) o << ", lhead=cluster_" << id(r->to);
    if (r->ev == Ev::fault || r->ev == Ev::timeout) o << ", color=red";
    o << "];\n";
  }
  o << "}\n";
  return o.str();
}

}  // namespace crease::fold
