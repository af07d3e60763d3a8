// swap {instance, library, params?}: hot-swap at a cycle boundary, state carried.
#include "core/control/protocol.h"
#include "core/daemon/commands/commands.h"

namespace crease::daemon {

nlohmann::json swap_command(const nlohmann::json& req, CommandContext& ctx) {
  const std::string instance = control::require_string(req, "instance");
  const std::string library = control::require_string(req, "library");
  const auto params = params_argument(req, "params", "swap", instance);
  return reply_failed_on_error([&] {
    ctx.host.swap(instance, library, params);
    return nlohmann::json{{"swapped", instance}, {"library", library}};
  });
}

}  // namespace crease::daemon
