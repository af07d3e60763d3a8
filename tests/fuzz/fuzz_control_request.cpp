// libFuzzer target: the control socket's request parser (core/control/request_parser.h), one
// input = one request line. Invariants: it never throws; what it accepts is an object naming a
// known command whose every argument is in the command's spec and of its type, and it accepts
// its own serialisation again; a refusal carries one of the parser's codes and a message.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/control/protocol.h"
#include "core/control/request_parser.h"

namespace ctl = crease::control;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  const ctl::ParsedRequest p = ctl::parse_request(line);
  if (!p.ok()) {
    if (p.error_code != ctl::kErrorMalformed && p.error_code != ctl::kErrorUnknownCommand &&
        p.error_code != ctl::kErrorBadArgument) {
      __builtin_trap();
    }
    if (p.error_message.empty()) __builtin_trap();
    (void)ctl::to_line(ctl::make_error(p.id, p.error_code, p.error_message));  // never throws
    return 0;
  }
  if (!p.request.is_object() || !p.request["cmd"].is_string()) __builtin_trap();
  const ctl::CommandSpec* spec = ctl::find_command_spec(p.request["cmd"].get<std::string>());
  if (spec == nullptr) __builtin_trap();
  for (const auto& [key, value] : p.request.items()) {
    if (key == "id" || key == "cmd") continue;
    bool listed = false;
    for (const ctl::ArgSpec& a : spec->args) listed |= key == a.name;
    if (!listed) __builtin_trap();
    if (!value.is_null() && spec->name == "param" && key == "value" && !value.is_number()) __builtin_trap();
  }
  const std::string again = p.request.dump(-1, ' ', false, nlohmann::json::error_handler_t::strict);
  const ctl::ParsedRequest q = ctl::parse_request(again);
  if (!q.ok() || q.request != p.request) __builtin_trap();
  return 0;
}
