// The control protocol: newline-delimited JSON over a Unix domain socket.
//
//   request: {"id": <any, echoed>, "cmd": "status", ...arguments}
//   reply:   {"id": ..., "ok": true,  "result": <any>}
//            {"id": ..., "ok": false, "error": {"code": "...", "message": "..."}}
//
// Commands (the daemon implements them; ControlServer frames, checks and dispatches):
//   status, loops, plugins, ports, stats, stop, threads            (no arguments)
//   load        instance, library, loop, order, [params (object), ports (object of strings)]
//   unload      instance
//   swap        instance, library, [params (object)]
//   activate    instance
//   deactivate  instance
//   param       action ("get" | "set"), instance, key, [value (a JSON number, set)]
//   report      format ("html" | "json" | "text")  -> result {"format":..., "content": "..."}
// Every request is checked against command_specs() before a handler sees it
// (request_parser.h): no argument outside the command's list, each of its JSON type.
// Error codes: see the kError* constants.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace crease::control {

inline constexpr char kErrorMalformed[] = "malformed";  // not JSON, not an object, a key twice
inline constexpr char kErrorUnknownCommand[] = "unknown_command";
inline constexpr char kErrorBadArgument[] = "bad_argument";      // missing / mistyped argument
inline constexpr char kErrorLineTooLong[] = "line_too_long";     // then disconnected
inline constexpr char kErrorTimeout[] = "timeout";               // half-sent line; disconnected
inline constexpr char kErrorTooManyClients[] = "too_many_clients";
inline constexpr char kErrorPermissionDenied[] = "permission_denied";
inline constexpr char kErrorFailed[] = "failed";                 // the command itself failed
inline constexpr char kErrorInternal[] = "internal";             // handler threw unexpectedly
inline constexpr char kErrorBusy[] = "busy";  // over the client's request rate; not handled

// The JSON type an argument must have: string (non-empty, no NUL), integer (a JSON integer),
// number (a finite JSON number; never a string), object, string_map (an object of strings).
enum class ArgType { string, integer, number, object, string_map };
struct ArgSpec {
  const char* name;
  ArgType type;
};
// A command and every argument it may take besides "id" and "cmd" (which are required is
// the handler's to say).
struct CommandSpec {
  std::string_view name;
  std::vector<ArgSpec> args;
};

// Every command the protocol defines: the one list (a new command is a row here).
[[nodiscard]] const std::vector<CommandSpec>& command_specs();
// The spec of CMD, or nullptr.
[[nodiscard]] const CommandSpec* find_command_spec(std::string_view cmd);
[[nodiscard]] const char* to_string(ArgType t) noexcept;

// Every command the protocol defines, in documentation order (command_specs()' names).
[[nodiscard]] const std::vector<std::string>& known_commands();
[[nodiscard]] bool is_known_command(std::string_view cmd);

// TEXT quoted for a message: control characters (NUL included) as \u00XX, the rest as is.
[[nodiscard]] std::string printable(std::string_view text);

// Thrown by a RequestHandler to reply {"ok": false, "error": {code, message}}. The reply
// carries message(), the whole string (what() stops at a NUL).
class RequestError : public std::runtime_error {
 public:
  RequestError(std::string code, const std::string& message)
      : std::runtime_error(message), code_(std::move(code)), message_(message) {}
  [[nodiscard]] const std::string& code() const noexcept { return code_; }
  [[nodiscard]] const std::string& message() const noexcept { return message_; }

 private:
  std::string code_;
  std::string message_;
};

// Argument accessors for handlers: throw RequestError(kErrorBadArgument, ...) naming the
// command and the argument when it is missing or of the wrong type.
[[nodiscard]] std::string require_string(const nlohmann::json& request, const char* name);
[[nodiscard]] std::int64_t require_int(const nlohmann::json& request, const char* name);
[[nodiscard]] const nlohmann::json& require_arg(const nlohmann::json& request, const char* name);

[[nodiscard]] nlohmann::json make_ok(const nlohmann::json& id, nlohmann::json result);
[[nodiscard]] nlohmann::json make_error(const nlohmann::json& id, const std::string& code,
                                        const std::string& message);

// One reply line (JSON + '\n'); invalid UTF-8 in strings is replaced, never throws.
[[nodiscard]] std::string to_line(const nlohmann::json& reply);

}  // namespace crease::control
