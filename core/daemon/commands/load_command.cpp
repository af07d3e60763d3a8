// load {instance, library, loop, order, params?, ports?}: loads, configures, activates and
// schedules a new instance.
#include "core/control/protocol.h"
#include "core/daemon/commands/commands.h"

namespace crease::daemon {

nlohmann::json load_command(const nlohmann::json& req, CommandContext& ctx) {
  const std::string instance = control::require_string(req, "instance");
  InstanceSpec s;
  s.name = instance;
  s.library = control::require_string(req, "library");
  s.loop = control::require_string(req, "loop");
  const std::int64_t order = control::require_int(req, "order");
  if (order < -1000000 || order > 1000000) {  // the configuration's range
    throw control::RequestError(control::kErrorBadArgument, "load: order must be in [-1000000, 1000000]");
  }
  s.order = static_cast<int>(order);
  if (auto p = params_argument(req, "params", "load", instance)) s.params = *p;
  if (req.contains("ports") && !req["ports"].is_null()) {
    if (!req["ports"].is_object()) {
      throw control::RequestError(control::kErrorBadArgument, "load: 'ports' must be an object of strings");
    }
    for (const auto& [k, v] : req["ports"].items()) {
      if (!v.is_string()) throw control::RequestError(control::kErrorBadArgument, "load: ports values must be strings");
      s.ports[k] = v.get<std::string>();
    }
  }
  return reply_failed_on_error([&] {
    ctx.host.add_instance(s);
    return nlohmann::json{{"loaded", instance}};
  });
}

}  // namespace crease::daemon
