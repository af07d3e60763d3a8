// Must not compile: a payload that grew without its pinned size changing is refused at build
// time, with the reason (core/port_types/payload_layout.h). The shipped payloads pin theirs at
// the end of their headers, compiled by everything that includes them.
#include "core/port_types/arm.h"

namespace {
struct GrownArmCommand {  // ArmCommand with one more field, pinned at ArmCommand's figures
  crease::ArmCommand old;
  double extra_rad;
};
}  // namespace

CREASE_PORT_PAYLOAD_LAYOUT(GrownArmCommand, sizeof(crease::ArmCommand), alignof(crease::ArmCommand));
