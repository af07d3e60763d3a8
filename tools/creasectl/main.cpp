// creasectl: steers a running creased through its control socket.
//
//   creasectl [--socket PATH] [--json] [--timeout S] COMMAND ...
//
// Exit status: 0 done; 1 the daemon answered with an error; 2 bad command line;
// 3 creased is not running (or the connection broke); 4 permission denied.
#include <fstream>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "core/control/control_client.h"
#include "core/control/protocol.h"
#include "core/control/socket_path.h"
#include "tools/creasectl/human_format.h"
#include "tools/creasectl/sequence_command.h"

namespace {

using nlohmann::json;
namespace ctl = crease::control;

constexpr int kExitFailed = 1;
constexpr int kExitNotRunning = 3;
constexpr int kExitPermission = 4;

struct Options {
  std::string socket = ctl::default_socket_path();
  bool raw_json = false;
  double timeout_s = 10;
  // arguments shared by subcommands
  std::string instance, library, loop, key, value, format = "text", out;
  long long order = 0;
};

// Prints the reply; returns the exit status.
int show(const Options& o, const std::string& cmd, const json& reply) {
  if (o.raw_json) std::cout << reply.dump(2, ' ', false, json::error_handler_t::replace) << "\n";
  if (reply.value("ok", false) != true) {
    const json err = reply.value("error", json::object());
    const std::string code = err.value("code", "?");
    std::cerr << "creasectl: " << cmd << ": " << err.value("message", "request failed") << " ("
              << code << ")\n";
    return code == ctl::kErrorPermissionDenied ? kExitPermission : kExitFailed;
  }
  const json result = reply.value("result", json());
  if (cmd == "report") {
    const std::string content = result.value("content", "");
    if (!o.out.empty()) {
      std::ofstream f(o.out, std::ios::binary | std::ios::trunc);
      f << content;
      f.close();
      if (!f) {
        std::cerr << "creasectl: report: cannot write " << o.out << "\n";
        return kExitFailed;
      }
      if (!o.raw_json) std::cout << "report (" << o.format << ") written to " << o.out << "\n";
    } else if (!o.raw_json) {
      std::cout << content;
    }
    return 0;
  }
  if (!o.raw_json) {
    if (result.is_null() || (result.is_object() && result.empty())) {
      std::cout << cmd << ": ok\n";
    } else {
      std::cout << crease::ctl::format_human(result);
    }
  }
  return 0;
}

int run(const Options& o, const std::string& cmd, const json& request) {
  try {
    ctl::ControlClient client(o.socket, std::chrono::milliseconds(static_cast<long>(o.timeout_s * 1000)));
    return show(o, cmd, client.request(request));
  } catch (const ctl::ClientError& e) {
    using Kind = ctl::ClientError::Kind;
    std::cerr << "creasectl: " << e.what();
    if (e.kind() == Kind::not_running) {
      std::cerr << "\n  start it with: creased --config FILE   (or pass --socket PATH)\n";
      return kExitNotRunning;
    }
    std::cerr << "\n";
    if (e.kind() == Kind::permission) return kExitPermission;
    return e.kind() == Kind::io ? kExitNotRunning : kExitFailed;
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"creasectl: control a running creased over its Unix socket"};
  app.set_help_all_flag("--help-all", "help for every command");
  app.add_option("--socket", o.socket, "control socket (default: " + o.socket + ")");
  app.add_flag("--json", o.raw_json, "print the raw JSON reply");
  app.add_option("--timeout", o.timeout_s, "seconds to wait for a reply")->check(CLI::PositiveNumber);
  app.require_subcommand(1);

  json request;
  std::string cmd;
  auto simple = [&](const char* name, const char* help) {
    app.add_subcommand(name, help)->callback([&, name] { cmd = name; request = {{"cmd", name}}; });
  };
  simple("status", "daemon state, uptime, loops and plugin counts");
  simple("loops", "loops with rate, priority, CPU and timing");
  simple("threads", "every thread of the daemon: CPUs, policy, priority; where non-RT threads run");
  simple("plugins", "plugin instances with library, loop, order and state");
  simple("ports", "ports with type, writer and readers");
  simple("stats", "timing statistics and control-server counters");
  simple("stop", "stop the daemon: safe outputs, deactivate, final report");

  auto* load = app.add_subcommand("load", "load and activate a plugin instance");
  load->add_option("INSTANCE", o.instance, "instance name")->required();
  load->add_option("LIBRARY", o.library, "library (crease_counter or a path)")->required();
  load->add_option("--loop", o.loop, "loop to run in")->required();
  load->add_option("--order", o.order, "run order within the loop")->required();
  load->callback([&] {
    cmd = "load";
    request = {{"cmd", "load"}, {"instance", o.instance}, {"library", o.library},
               {"loop", o.loop}, {"order", o.order}};
  });

  auto instance_cmd = [&](const char* name, const char* help) {
    auto* sub = app.add_subcommand(name, help);
    sub->add_option("INSTANCE", o.instance, "instance name")->required();
    sub->callback([&, name] { cmd = name; request = {{"cmd", name}, {"instance", o.instance}}; });
  };
  instance_cmd("unload", "deactivate and unload a plugin instance");
  instance_cmd("activate", "activate a plugin instance");
  instance_cmd("deactivate", "deactivate a plugin instance (outputs to safe values)");

  auto* swap = app.add_subcommand("swap", "hot-swap an instance to another library, keeping state");
  swap->add_option("INSTANCE", o.instance, "instance name")->required();
  swap->add_option("LIBRARY", o.library, "new library")->required();
  swap->callback([&] {
    cmd = "swap";
    request = {{"cmd", "swap"}, {"instance", o.instance}, {"library", o.library}};
  });

  auto* param = app.add_subcommand("param", "read or change a plugin parameter");
  param->require_subcommand(1);
  auto* pget = param->add_subcommand("get", "read a parameter");
  pget->add_option("INSTANCE", o.instance, "instance name")->required();
  pget->add_option("KEY", o.key, "parameter name")->required();
  pget->callback([&] {
    cmd = "param";
    request = {{"cmd", "param"}, {"action", "get"}, {"instance", o.instance}, {"key", o.key}};
  });
  auto* pset = param->add_subcommand("set", "change a parameter (validated by the plugin)");
  pset->add_option("INSTANCE", o.instance, "instance name")->required();
  pset->add_option("KEY", o.key, "parameter name")->required();
  pset->add_option("VALUE", o.value, "new value, a number (sent as a JSON number)")
      ->required()
      ->check(CLI::Validator(
          [](std::string& v) {
            return crease::ctl::parse_cli_value(v).is_number() ? std::string() : "not a number: '" + v + "'";
          },
          "NUMBER"));
  pset->callback([&] {
    cmd = "param";
    request = {{"cmd", "param"}, {"action", "set"}, {"instance", o.instance}, {"key", o.key},
               {"value", crease::ctl::parse_cli_value(o.value)}};
  });

  crease::ctl::add_sequence_command(app, cmd, request);

  auto* report = app.add_subcommand("report", "timing report of the run so far");
  report->add_option("--format", o.format, "html, json or text")
      ->check(CLI::IsMember({"html", "json", "text"}));
  report->add_option("--out", o.out, "write to FILE instead of standard output");
  report->callback([&] { cmd = "report"; request = {{"cmd", "report"}, {"format", o.format}}; });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // help: 0; any usage error: 2
  }
  return run(o, cmd, request);
}
