#include "core/control/request_parser.h"

#include <cmath>
#include <set>
#include <vector>

#include "core/control/protocol.h"

namespace crease::control {
namespace {

using json = nlohmann::json;

ParsedRequest failure(json id, const char* code, std::string message) {
  ParsedRequest p;
  p.id = std::move(id);
  p.error_code = code;
  p.error_message = std::move(message);
  return p;
}

bool has_nul(const std::string& s) { return s.find('\0') != std::string::npos; }

// "" when V is of type T, else why not.
std::string type_error(const json& v, ArgType t) {
  switch (t) {
    case ArgType::string:
      if (!v.is_string() || v.get_ref<const std::string&>().empty()) return "must be a non-empty string";
      if (has_nul(v.get_ref<const std::string&>())) {
        return "contains a NUL character: '" + printable(v.get_ref<const std::string&>()) + "'";
      }
      return "";
    case ArgType::integer:
      if (!v.is_number_integer()) return "must be an integer (a JSON number)";
      if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX)) {
        return "must be an integer of 64 bits";
      }
      return "";
    case ArgType::number:
      if (!v.is_number()) return "must be a number (a JSON number, not a string)";
      if (v.is_number_float() && !std::isfinite(v.get<double>())) return "must be a finite number";
      return "";
    case ArgType::object:
      return v.is_object() ? "" : "must be an object";
    case ArgType::string_map:
      if (!v.is_object()) return "must be an object of strings";
      for (const auto& [k, s] : v.items()) {
        if (!s.is_string() || s.get_ref<const std::string&>().empty() || has_nul(s.get_ref<const std::string&>())) {
          return "must be an object of non-empty strings without NUL ('" + printable(k) + "' is not)";
        }
      }
      return "";
  }
  return "has an unknown type";
}

}  // namespace

ParsedRequest parse_request(std::string_view line) {
  // The callback sees every key as it is read: one set of keys per open object.
  std::vector<std::set<std::string>> open_objects;
  std::string duplicate;
  bool has_duplicate = false;
  const json::parser_callback_t track = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start: open_objects.emplace_back(); break;
      case json::parse_event_t::object_end:
        if (!open_objects.empty()) open_objects.pop_back();
        break;
      case json::parse_event_t::key:
        if (!open_objects.empty() && !open_objects.back().insert(parsed.get<std::string>()).second && !has_duplicate) {
          has_duplicate = true;
          duplicate = parsed.get<std::string>();
        }
        break;
      default: break;
    }
    return true;
  };
  json req = json::parse(line.begin(), line.end(), track, false);
  if (req.is_discarded()) return failure(nullptr, kErrorMalformed, "request is not JSON");
  if (has_duplicate) return failure(nullptr, kErrorMalformed, "request has the key '" + printable(duplicate) + "' twice");
  if (!req.is_object()) return failure(nullptr, kErrorMalformed, "request is not a JSON object");
  json id = req.contains("id") ? req["id"] : json(nullptr);
  const auto cmd = req.find("cmd");
  if (cmd == req.end() || !cmd->is_string()) return failure(std::move(id), kErrorMalformed, "request has no string 'cmd'");
  const std::string& name = cmd->get_ref<const std::string&>();
  const CommandSpec* spec = find_command_spec(name);
  if (spec == nullptr) return failure(std::move(id), kErrorUnknownCommand, "unknown command '" + printable(name) + "'");
  for (const auto& [key, value] : req.items()) {
    if (key == "id" || key == "cmd") continue;
    const ArgSpec* arg = nullptr;
    for (const ArgSpec& a : spec->args) {
      if (key == a.name) arg = &a;
    }
    if (arg == nullptr) {
      return failure(std::move(id), kErrorBadArgument, "'" + name + "' takes no argument '" + printable(key) + "'");
    }
    if (value.is_null()) continue;  // the same as absent; the handler says when it is needed
    const std::string why = type_error(value, arg->type);
    if (!why.empty()) {
      return failure(std::move(id), kErrorBadArgument, "'" + name + "': argument '" + key + "' " + why);
    }
  }
  ParsedRequest p;
  p.id = std::move(id);
  p.request = std::move(req);
  return p;
}

}  // namespace crease::control
