// param {action: get | set, instance, key, value (set)}: a tunable parameter, read or set; a
// set value applies at the next cycle boundary after the plugin validated it.
#include <cmath>
#include <optional>

#include "core/control/protocol.h"
#include "core/daemon/commands/commands.h"

namespace crease::daemon {
namespace {

// A finite JSON number, else nullopt: a string is never read as one ("0x10", "1e999").
std::optional<double> number_of(const nlohmann::json& value) {
  if (!value.is_number()) return std::nullopt;
  const double v = value.get<double>();
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

}  // namespace

nlohmann::json param_command(const nlohmann::json& req, CommandContext& ctx) {
  const std::string instance = control::require_string(req, "instance");
  const std::string action = control::require_string(req, "action");
  const std::string key = control::require_string(req, "key");
  if (action == "get") {
    const auto v = ctx.host.get_param(instance, key);
    if (!v) {
      throw control::RequestError(control::kErrorFailed,
                                  "instance '" + instance + "' has no tunable parameter '" + key + "'");
    }
    return {{"instance", instance}, {"key", key}, {"value", *v}};
  }
  if (action == "set") {
    const auto v = number_of(control::require_arg(req, "value"));
    if (!v) throw control::RequestError(control::kErrorBadArgument, "param set: value must be a number");
    const std::string why = ctx.host.set_param(instance, key, *v);
    if (!why.empty()) throw control::RequestError(control::kErrorFailed, why);
    return {{"instance", instance}, {"key", key}, {"value", *v}, {"applies", "at the next cycle boundary"}};
  }
  throw control::RequestError(control::kErrorBadArgument,
                              "param: action must be get or set, not '" + control::printable(action) + "'");
}

}  // namespace crease::daemon
