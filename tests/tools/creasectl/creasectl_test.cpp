// Runs the creasectl binary against an in-process ControlServer with a fake daemon handler:
// requests it builds, human and --json output, report files, exit statuses and messages.
#include <doctest/doctest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>

#include "core/control/control_server.h"
#include "core/control/protocol.h"

namespace ctl = crease::control;
using nlohmann::json;

namespace {

struct FakeDaemon : ctl::RequestHandler {
  std::mutex m;
  json last;
  json handle(const json& request) override {
    {
      std::lock_guard<std::mutex> lock(m);
      last = request;
    }
    const std::string cmd = request.at("cmd");
    if (cmd == "status") return {{"state", "running"}, {"uptime_s", 1.4490754060000002}, {"rate_hz", 1000.0},
              {"tiny", 0.00002}, {"loops", 2}};
    if (cmd == "plugins") {
      return json::array({{{"name", "counter"}, {"library", "crease_counter"}, {"order", 10}},
                          {{"name", "sheet_model_long_name"}, {"library", "x"}, {"order", 2}}});
    }
    if (cmd == "swap") {
      if (ctl::require_string(request, "library") == "missing") {
        throw ctl::RequestError(ctl::kErrorFailed, "no library 'missing' in the plugin dirs");
      }
      return {{"instance", request["instance"]}, {"swapped", true}};
    }
    if (cmd == "report") {
      return {{"format", request.at("format")}, {"content", "<html>report</html>\n"}};
    }
    return json::object();
  }
  json last_request() {
    std::lock_guard<std::mutex> lock(m);
    return last;
  }
};

struct Run {
  int status = -1;
  std::string out, err;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::string kDir = "/tmp/crease_ctl_cli_" + std::to_string(::getpid());

Run creasectl(const std::string& args, const std::string& prefix = "") {
  const std::string out = kDir + "/out.txt", err = kDir + "/err.txt";
  const std::string cmd = prefix + std::string(CREASE_BIN_DIR) + "/creasectl " + args + " >" + out +
                          " 2>" + err;
  const int rc = std::system(cmd.c_str());
  Run r;
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace

TEST_CASE("creasectl talks to the control socket") {
  std::filesystem::create_directories(kDir);
  FakeDaemon daemon;
  ctl::ServerOptions opt;
  opt.socket_path = kDir + "/run/creased.sock";
  ctl::ControlServer server(opt, daemon);
  server.start();
  const std::string sock = "--socket " + opt.socket_path + " ";

  Run r = creasectl(sock + "status");
  CHECK(r.status == 0);
  CHECK(r.out == "loops: 2\nrate_hz: 1000\nstate: running\ntiny: 2e-05\nuptime_s: 1.449\n");

  r = creasectl(sock + "--json status");
  CHECK(r.status == 0);
  const json j = json::parse(r.out);
  CHECK(j["ok"] == true);
  CHECK(j["result"]["state"] == "running");

  r = creasectl(sock + "plugins");
  CHECK(r.status == 0);
  CHECK(r.out ==
        "name                   library         order\n"
        "counter                crease_counter  10\n"
        "sheet_model_long_name  x               2\n");

  r = creasectl(sock + "load counter2 crease_counter --loop control --order 30");
  CHECK(r.status == 0);
  CHECK(r.out == "load: ok\n");
  CHECK(daemon.last_request() == json{{"cmd", "load"}, {"id", 1}, {"instance", "counter2"},
                                      {"library", "crease_counter"}, {"loop", "control"},
                                      {"order", 30}});

  r = creasectl(sock + "param set counter step 2.5");
  CHECK(r.status == 0);
  CHECK(daemon.last_request()["value"] == 2.5);
  CHECK(daemon.last_request()["action"] == "set");
  // Parameters are numbers: a word or "0x10" never leaves creasectl (the daemon refuses strings).
  r = creasectl(sock + "param set counter mode fast");
  CHECK(r.status == 2);
  CHECK(r.err.find("not a number: 'fast'") != std::string::npos);
  CHECK(daemon.last_request()["value"] == 2.5);
  CHECK(creasectl(sock + "param set counter mode 0x10").status == 2);
  r = creasectl(sock + "param get counter step");
  CHECK(daemon.last_request() ==
        json{{"cmd", "param"}, {"id", 1}, {"action", "get"}, {"instance", "counter"}, {"key", "step"}});
  // sequence: the fold_sequence instance's `command` tunable through param set.
  r = creasectl(sock + "sequence pause");
  CHECK(r.status == 0);
  CHECK(daemon.last_request() == json{{"cmd", "param"}, {"id", 1}, {"action", "set"}, {"instance", "fold"},
                                      {"key", "command"}, {"value", 2}});
  int code = 1;
  for (const char* w : {"start", "pause", "resume", "abort", "step"}) {
    r = creasectl(sock + "sequence " + w + " --instance fold2");
    CHECK(r.status == 0);
    CHECK(daemon.last_request()["instance"] == "fold2");
    CHECK(daemon.last_request()["value"] == code++);
  }
  r = creasectl(sock + "sequence jump");
  CHECK(r.status == 2);
  for (const char* c : {"unload", "activate", "deactivate"}) {
    r = creasectl(sock + c + " counter");
    CHECK(r.status == 0);
    CHECK(daemon.last_request()["cmd"] == c);
    CHECK(daemon.last_request()["instance"] == "counter");
  }
  for (const char* c : {"loops", "ports", "stats", "stop"}) {
    CHECK(creasectl(sock + c).status == 0);
    CHECK(daemon.last_request()["cmd"] == c);
  }

  r = creasectl(sock + "swap counter crease_counter_v2");
  CHECK(r.status == 0);
  CHECK(r.out == "instance: counter\nswapped: yes\n");
  r = creasectl(sock + "swap counter missing");
  CHECK(r.status == 1);
  CHECK(r.err == "creasectl: swap: no library 'missing' in the plugin dirs (failed)\n");

  const std::string file = kDir + "/r.html";
  r = creasectl(sock + "report --format html --out " + file);
  CHECK(r.status == 0);
  CHECK(daemon.last_request()["format"] == "html");
  CHECK(slurp(file) == "<html>report</html>\n");
  CHECK(r.out == "report (html) written to " + file + "\n");
  r = creasectl(sock + "report --format json");
  CHECK(r.out == "<html>report</html>\n");  // content goes to stdout as is

  // Usage errors: exit 2, nothing sent.
  CHECK(creasectl(sock + "report --format pdf").status == 2);
  CHECK(creasectl(sock + "load x y").status == 2);
  CHECK(creasectl(sock).status == 2);

  // Refused by SO_PEERCRED (socket loosened so the kernel lets the other uid connect).
  if (::geteuid() == 0 && std::system("command -v setpriv >/dev/null 2>&1") == 0) {
    REQUIRE(::chmod(kDir.c_str(), 0755) == 0);
    REQUIRE(::chmod((kDir + "/run").c_str(), 0755) == 0);
    REQUIRE(::chmod(opt.socket_path.c_str(), 0666) == 0);
    REQUIRE(::chmod((kDir + "/out.txt").c_str(), 0666) == 0);
    REQUIRE(::chmod((kDir + "/err.txt").c_str(), 0666) == 0);
    r = creasectl(sock + "status", "setpriv --reuid=65534 --regid=65534 --clear-groups ");
    CHECK(r.status == 4);
    CHECK(r.err.find("(permission_denied)") != std::string::npos);
  } else {
    MESSAGE("SKIPPED: peer refusal needs root and setpriv");
  }

  server.stop();
  r = creasectl(sock + "status");
  CHECK(r.status == 3);
  CHECK(r.err.find("creased is not running (no listener on " + opt.socket_path + ")") !=
        std::string::npos);
  std::filesystem::remove_all(kDir);
}
