// Human-readable rendering of control replies for creasectl (the default; --json prints raw).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace crease::ctl {

// Objects become "key: value" lines (nested objects indented), lists of objects become
// aligned tables with one column per key, lists of scalars a comma-separated line.
[[nodiscard]] std::string format_human(const nlohmann::json& value);

// A command-line value for `param set`: JSON when it parses (2.5, true, [1,2], "x"),
// otherwise the text as a string.
[[nodiscard]] nlohmann::json parse_cli_value(const std::string& text);

}  // namespace crease::ctl
