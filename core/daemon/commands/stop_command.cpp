// stop: creased stops cleanly (the main thread sees the request within its 50 ms tick).
#include "core/daemon/commands/commands.h"

namespace crease::daemon {

nlohmann::json stop_command(const nlohmann::json&, CommandContext& ctx) {
  ctx.stop("creasectl stop");
  return {{"stopping", true}};
}

}  // namespace crease::daemon
