// unload, activate, deactivate {instance}: the same shape, one host call each.
#include "core/control/protocol.h"
#include "core/daemon/commands/commands.h"

namespace crease::daemon {

nlohmann::json unload_command(const nlohmann::json& req, CommandContext& ctx) {
  const std::string instance = control::require_string(req, "instance");
  return reply_failed_on_error([&] {
    ctx.host.unload(instance);
    return nlohmann::json{{"unloaded", instance}};
  });
}

nlohmann::json activate_command(const nlohmann::json& req, CommandContext& ctx) {
  const std::string instance = control::require_string(req, "instance");
  return reply_failed_on_error([&] {
    ctx.host.activate(instance);
    return nlohmann::json{{"activated", instance}};
  });
}

nlohmann::json deactivate_command(const nlohmann::json& req, CommandContext& ctx) {
  const std::string instance = control::require_string(req, "instance");
  return reply_failed_on_error([&] {
    ctx.host.deactivate(instance);
    return nlohmann::json{{"deactivated", instance}};
  });
}

}  // namespace crease::daemon
