// The control protocol: newline-delimited JSON over a Unix domain socket.
//
//   request: {"id": <any, echoed>, "cmd": "status", ...arguments}
//   reply:   {"id": ..., "ok": true,  "result": <any>}
//            {"id": ..., "ok": false, "error": {"code": "...", "message": "..."}}
//
// Commands (the daemon implements them; ControlServer frames and dispatches):
//   status, loops, plugins, ports, stats, stop                     (no arguments)
//   load        instance, library, loop, order
//   unload      instance
//   swap        instance, library
//   activate    instance
//   deactivate  instance
//   param       action ("get" | "set"), instance, key, [value (set)]
//   report      format ("html" | "json" | "text")  -> result {"format":..., "content": "..."}
// Error codes: see the kError* constants.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace crease::control {

inline constexpr char kErrorMalformed[] = "malformed";           // not JSON / not an object
inline constexpr char kErrorUnknownCommand[] = "unknown_command";
inline constexpr char kErrorBadArgument[] = "bad_argument";      // missing / mistyped argument
inline constexpr char kErrorLineTooLong[] = "line_too_long";     // then disconnected
inline constexpr char kErrorTimeout[] = "timeout";               // half-sent line; disconnected
inline constexpr char kErrorTooManyClients[] = "too_many_clients";
inline constexpr char kErrorPermissionDenied[] = "permission_denied";
inline constexpr char kErrorFailed[] = "failed";                 // the command itself failed
inline constexpr char kErrorInternal[] = "internal";             // handler threw unexpectedly

// Every command the protocol defines, in documentation order.
[[nodiscard]] const std::vector<std::string>& known_commands();
[[nodiscard]] bool is_known_command(std::string_view cmd);

// Thrown by a RequestHandler to reply {"ok": false, "error": {code, message}}.
class RequestError : public std::runtime_error {
 public:
  RequestError(std::string code, const std::string& message)
      : std::runtime_error(message), code_(std::move(code)) {}
  [[nodiscard]] const std::string& code() const noexcept { return code_; }

 private:
  std::string code_;
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
