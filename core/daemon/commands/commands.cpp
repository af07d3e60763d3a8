#include "core/daemon/commands/commands.h"

#include <utility>

#include "core/control/protocol.h"

namespace crease::daemon {

CommandHandler find_command(std::string_view cmd) {
  static constexpr std::pair<std::string_view, CommandHandler> kTable[] = {
      {"status", status_command},   {"loops", loops_command},         {"plugins", plugins_command},
      {"ports", ports_command},     {"stats", stats_command},         {"stop", stop_command},
      {"report", report_command},   {"load", load_command},           {"unload", unload_command},
      {"activate", activate_command}, {"deactivate", deactivate_command}, {"swap", swap_command},
      {"param", param_command},     {"threads", threads_command},
  };
  for (const auto& [name, handler] : kTable) {
    if (name == cmd) return handler;
  }
  return nullptr;
}

std::optional<Params> params_argument(const nlohmann::json& req, const char* key, const std::string& cmd,
                                      const std::string& instance) {
  if (!req.contains(key)) return std::nullopt;
  if (!req[key].is_object()) {
    throw control::RequestError(control::kErrorBadArgument, cmd + ": '" + key + "' must be an object");
  }
  return Params(YAML::Load(req[key].dump()), "request", instance + ".params");
}

nlohmann::json reply_failed_on_error(const std::function<nlohmann::json()>& fn) {
  try {
    return fn();
  } catch (const control::RequestError&) {
    throw;
  } catch (const std::exception& e) {
    throw control::RequestError(control::kErrorFailed, e.what());
  }
}

}  // namespace crease::daemon
