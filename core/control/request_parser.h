// One request line to a checked request, or the error the reply carries. Strict: what a
// handler gets is an object with a known string "cmd", no key twice at any depth (a repeated
// key would take the last value: {"cmd":"status","cmd":"stop"} would stop the daemon), no
// argument outside the command's spec (protocol.h) and each argument of its JSON type:
// strings non-empty and without NUL, numbers as JSON numbers only ("0x10" is a string),
// finite. Messages quote client text with printable(), whole, NUL included.
//
//   const ParsedRequest p = parse_request(line);
//   if (!p.ok()) reply(make_error(p.id, p.error_code, p.error_message));
//
// Pure (no I/O, no state); its cost is linear in the line's length. Fuzzed (tests/fuzz).
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace crease::control {

struct ParsedRequest {
  nlohmann::json request;     // the object, when ok()
  nlohmann::json id;          // the request's "id" to echo (null when there is none to trust)
  std::string error_code;     // empty when ok(); else kErrorMalformed, kErrorUnknownCommand, kErrorBadArgument
  std::string error_message;

  [[nodiscard]] bool ok() const noexcept { return error_code.empty(); }
};

[[nodiscard]] ParsedRequest parse_request(std::string_view line);

}  // namespace crease::control
