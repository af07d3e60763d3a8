// creased's control commands: one handler per command (grouped only where several commands
// share one shape: the read-only views, and unload/activate/deactivate), looked up by name.
// Handlers run on the control server's thread (non-RT), one request at a time, after the
// server checked that the request is a JSON object naming a known command. A refused request
// throws control::RequestError (bad_argument, failed); the reply format is the server's.
// A new command: a handler file here, a line in commands.cpp's table, its name in
// core/control/protocol.cpp, and a row in README.md's table.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/control/control_server.h"
#include "core/daemon/report_builder.h"
#include "core/params.h"
#include "core/plugin_host.h"

namespace crease::daemon {

// What a handler may read and change.
struct CommandContext {
  PluginHost& host;
  const RunFacts& facts;
  const control::ControlServer* server;                 // null when there is none (tests)
  std::function<void(const std::string& reason)> stop;  // asks creased to stop, saying why
};

using CommandHandler = nlohmann::json (*)(const nlohmann::json& request, CommandContext& ctx);

// The handler of `cmd`, or nullptr when creased implements no such command.
[[nodiscard]] CommandHandler find_command(std::string_view cmd);

// --- helpers shared by the handlers ---
// The argument `key` as plugin parameters (messages name them INSTANCE.params), or nullopt
// when absent. Throws RequestError(bad_argument) "CMD: 'KEY' must be an object".
[[nodiscard]] std::optional<Params> params_argument(const nlohmann::json& request, const char* key,
                                                    const std::string& cmd, const std::string& instance);
// Runs fn; an exception other than RequestError (a refused load, swap, ...) becomes
// RequestError(failed) with its message.
nlohmann::json reply_failed_on_error(const std::function<nlohmann::json()>& fn);

// --- the handlers (files of this folder) ---
nlohmann::json status_command(const nlohmann::json& request, CommandContext& ctx);   // view_commands.cpp
nlohmann::json loops_command(const nlohmann::json& request, CommandContext& ctx);    // view_commands.cpp
nlohmann::json threads_command(const nlohmann::json& request, CommandContext& ctx);  // view_commands.cpp
nlohmann::json plugins_command(const nlohmann::json& request, CommandContext& ctx);  // view_commands.cpp
nlohmann::json ports_command(const nlohmann::json& request, CommandContext& ctx);    // view_commands.cpp
nlohmann::json stats_command(const nlohmann::json& request, CommandContext& ctx);    // view_commands.cpp
nlohmann::json stop_command(const nlohmann::json& request, CommandContext& ctx);
nlohmann::json report_command(const nlohmann::json& request, CommandContext& ctx);
nlohmann::json load_command(const nlohmann::json& request, CommandContext& ctx);
nlohmann::json unload_command(const nlohmann::json& request, CommandContext& ctx);      // lifecycle_commands.cpp
nlohmann::json activate_command(const nlohmann::json& request, CommandContext& ctx);    // lifecycle_commands.cpp
nlohmann::json deactivate_command(const nlohmann::json& request, CommandContext& ctx);  // lifecycle_commands.cpp
nlohmann::json swap_command(const nlohmann::json& request, CommandContext& ctx);
nlohmann::json param_command(const nlohmann::json& request, CommandContext& ctx);

}  // namespace crease::daemon
