#include "core/daemon/sequences.h"

#include <string>

#include "core/port_types/sequence_status.h"

namespace crease::daemon {
namespace {

const char* phase_name(std::uint8_t p) {
  switch (p) {
    case SequenceStatus::idle: return "idle";
    case SequenceStatus::running: return "running";
    case SequenceStatus::paused: return "paused";
    case SequenceStatus::done: return "done";
    case SequenceStatus::aborted: return "aborted";
    default: return "?";
  }
}

// A plugin's text, terminated within its array whatever it wrote.
template <std::size_t N>
std::string text(const char (&s)[N]) {
  std::size_t n = 0;
  while (n < N && s[n] != '\0') ++n;
  return std::string(s, n);
}

}  // namespace

nlohmann::json sequences_view(const PortRegistry& ports) {
  nlohmann::json out = nlohmann::json::array();
  for (const PortInfo& p : ports.list()) {
    if (p.kind != PortKind::latest || p.type_name != SequenceStatus::kPortType || p.size != sizeof(SequenceStatus))
      continue;
    const rt::LatestChannel* ch = ports.find_latest(p.name);
    SequenceStatus s;
    if (ch == nullptr || !ch->read(&s, 0).has_data()) continue;
    out.push_back({{"port", p.name},
                   {"fold", text(s.fold)},
                   {"path", text(s.path)},
                   {"phase", phase_name(s.phase)},
                   {"time_in_state_s", s.time_in_state_s},
                   {"why", text(s.why)},
                   {"transitions", s.transitions},
                   {"aborts", s.aborts},
                   {"step_mode", s.step_mode != 0}});
  }
  return out;
}

}  // namespace crease::daemon
