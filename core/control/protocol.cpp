#include "core/control/protocol.h"

#include <algorithm>
#include <cstdio>

namespace crease::control {

const std::vector<CommandSpec>& command_specs() {
  using T = ArgType;
  static const std::vector<CommandSpec> specs = {
      {"status", {}},
      {"loops", {}},
      {"plugins", {}},
      {"ports", {}},
      {"load",
       {{"instance", T::string}, {"library", T::string}, {"loop", T::string}, {"order", T::integer},
        {"params", T::object}, {"ports", T::string_map}}},
      {"unload", {{"instance", T::string}}},
      {"swap", {{"instance", T::string}, {"library", T::string}, {"params", T::object}}},
      {"activate", {{"instance", T::string}}},
      {"deactivate", {{"instance", T::string}}},
      {"param", {{"action", T::string}, {"instance", T::string}, {"key", T::string}, {"value", T::number}}},
      {"stats", {}},
      {"report", {{"format", T::string}}},
      {"stop", {}},
      {"threads", {}},
  };
  return specs;
}

const CommandSpec* find_command_spec(std::string_view cmd) {
  for (const CommandSpec& c : command_specs()) {
    if (c.name == cmd) return &c;
  }
  return nullptr;
}

const char* to_string(ArgType t) noexcept {
  switch (t) {
    case ArgType::string: return "a non-empty string";
    case ArgType::integer: return "an integer";
    case ArgType::number: return "a number";
    case ArgType::object: return "an object";
    case ArgType::string_map: return "an object of strings";
  }
  return "?";
}

const std::vector<std::string>& known_commands() {
  static const std::vector<std::string> commands = [] {
    std::vector<std::string> out;
    for (const CommandSpec& c : command_specs()) out.emplace_back(c.name);
    return out;
  }();
  return commands;
}

bool is_known_command(std::string_view cmd) { return find_command_spec(cmd) != nullptr; }

std::string printable(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", c);
      out += buf;
    } else {
      out.push_back(ch);
    }
  }
  return out;
}

namespace {
std::string cmd_of(const nlohmann::json& request) {
  const auto it = request.find("cmd");
  return (it != request.end() && it->is_string()) ? printable(it->get_ref<const std::string&>()) : std::string("?");
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
  if (!v.is_number_integer() || (v.is_number_unsigned() && v.get<std::uint64_t>() > INT64_MAX)) {
    throw RequestError(kErrorBadArgument,
                       "'" + cmd_of(request) + "': argument '" + name + "' must be an integer");
  }
  return v.get<std::int64_t>();
}

// Built key by key: an initializer list builds each member as a two-item array first and then
// takes it apart (allocations per member, on every reply).
nlohmann::json make_ok(const nlohmann::json& id, nlohmann::json result) {
  nlohmann::json reply(nlohmann::json::value_t::object);
  reply["id"] = id;
  reply["ok"] = true;
  reply["result"] = std::move(result);
  return reply;
}

nlohmann::json make_error(const nlohmann::json& id, const std::string& code,
                          const std::string& message) {
  nlohmann::json reply(nlohmann::json::value_t::object);
  reply["id"] = id;
  reply["ok"] = false;
  nlohmann::json& error = reply["error"];
  error["code"] = code;
  error["message"] = message;
  return reply;
}

std::string to_line(const nlohmann::json& reply) {
  std::string s = reply.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  s.push_back('\n');
  return s;
}

}  // namespace crease::control
