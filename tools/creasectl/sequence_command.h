// `creasectl sequence start|pause|resume|abort|step [--instance NAME]`: steers a folding
// sequence (plugins/fold_sequence) through creased's `param set` path: the request sets the
// instance's tunable `command` (1 start, 2 pause, 3 resume, 4 abort, 5 step), which the plugin
// reads at its next cycle and resets. Its state is on `creasectl status` (`sequences`).
#pragma once

#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace crease::ctl {

// Adds the subcommand to app; when parsed, sets cmd and the request to send.
void add_sequence_command(CLI::App& app, std::string& cmd, nlohmann::json& request);

// The tunable's value for a sequence command's word, 0 for an unknown word.
[[nodiscard]] int sequence_command_code(const std::string& word);

}  // namespace crease::ctl
