// report {format: html | json | text}: the timing report as it is now, rendered.
#include "core/control/protocol.h"
#include "core/daemon/commands/commands.h"
#include "core/report/render.h"

namespace crease::daemon {

nlohmann::json report_command(const nlohmann::json& req, CommandContext& ctx) {
  const std::string f = control::require_string(req, "format");
  report::Format format;
  if (f == "html") format = report::Format::html;
  else if (f == "json") format = report::Format::json;
  else if (f == "text") format = report::Format::text;
  else throw control::RequestError(control::kErrorBadArgument, "report: format must be html, json or text, not '" + f + "'");
  return {{"format", f}, {"content", report::render(build_report(ctx.host, ctx.facts), format)}};
}

}  // namespace crease::daemon
