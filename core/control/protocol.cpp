#include "core/control/protocol.h"

#include <algorithm>

namespace crease::control {

const std::vector<std::string>& known_commands() {
  static const std::vector<std::string> commands = {
      "status", "loops",      "plugins", "ports", "load",   "unload", "swap",
      "activate", "deactivate", "param", "stats", "report", "stop", "threads"};
  return commands;
}

bool is_known_command(std::string_view cmd) {
  const auto& c = known_commands();
  return std::find(c.begin(), c.end(), cmd) != c.end();
}

namespace {
std::string cmd_of(const nlohmann::json& request) {
  const auto it = request.find("cmd");
  return (it != request.end() && it->is_string()) ? it->get<std::string>() : std::string("?");
}
}  // namespace

const nlohmann::json& require_arg(const nlohmann::json& request, const char* name) {
  const auto it = request.find(name);
  if (it == request.end() || it->is_null()) {
    throw RequestError(kErrorBadArgument,
                       "'" + cmd_of(request) + "' needs the argument '" + name + "'");
  }
  return *it;
}

std::string require_string(const nlohmann::json& request, const char* name) {
  const nlohmann::json& v = require_arg(request, name);
  if (!v.is_string() || v.get_ref<const std::string&>().empty()) {
    throw RequestError(kErrorBadArgument, "'" + cmd_of(request) + "': argument '" + name +
                                              "' must be a non-empty string");
  }
  return v.get<std::string>();
}

std::int64_t require_int(const nlohmann::json& request, const char* name) {
  const nlohmann::json& v = require_arg(request, name);
  if (!v.is_number_integer()) {
    throw RequestError(kErrorBadArgument,
                       "'" + cmd_of(request) + "': argument '" + name + "' must be an integer");
  }
  return v.get<std::int64_t>();
}

nlohmann::json make_ok(const nlohmann::json& id, nlohmann::json result) {
  return nlohmann::json{{"id", id}, {"ok", true}, {"result", std::move(result)}};
}

nlohmann::json make_error(const nlohmann::json& id, const std::string& code,
                          const std::string& message) {
  return nlohmann::json{
      {"id", id}, {"ok", false}, {"error", {{"code", code}, {"message", message}}}};
}

std::string to_line(const nlohmann::json& reply) {
  std::string s = reply.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  s.push_back('\n');
  return s;
}

}  // namespace crease::control
