// status, loops, threads, plugins, ports, stats: no arguments, the views of core/daemon/views.h.
#include "core/daemon/commands/commands.h"
#include "core/daemon/views.h"
#include "rt/clock.h"

namespace crease::daemon {

nlohmann::json status_command(const nlohmann::json&, CommandContext& ctx) {
  return status_view(ctx.host, ctx.facts, rt::now_ns(), ctx.server);
}

nlohmann::json loops_command(const nlohmann::json&, CommandContext& ctx) { return loops_view(ctx.host); }

nlohmann::json threads_command(const nlohmann::json&, CommandContext& ctx) { return threads_view(ctx.facts); }

nlohmann::json plugins_command(const nlohmann::json&, CommandContext& ctx) { return plugins_view(ctx.host); }

nlohmann::json ports_command(const nlohmann::json&, CommandContext& ctx) { return ports_view(ctx.host.ports()); }

nlohmann::json stats_command(const nlohmann::json&, CommandContext& ctx) { return stats_view(ctx.host, ctx.server); }

}  // namespace crease::daemon
