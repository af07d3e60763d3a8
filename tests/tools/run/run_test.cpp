// tools/run builds the `main-job` target only: creased, creasectl and every plugin
// config/sim.yaml loads, and no test (tools/test builds those). Checked on this build's graph
// (`ninja -t inputs`, the Ninja generator of every preset).
#include <doctest/doctest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/config/daemon_config.h"

namespace fs = std::filesystem;

namespace {
const fs::path kBuild = fs::path(CREASE_BIN_DIR).parent_path();  // CREASE_BIN_DIR is <build>/bin

// The lines `ninja -t TOOL TARGET` prints in this build folder.
std::vector<std::string> ninja_tool(const std::string& tool, const std::string& target) {
  const std::string cmd = "ninja -C " + kBuild.string() + " -t " + tool + " " + target + " 2>&1";
  FILE* f = popen(cmd.c_str(), "r");
  REQUIRE(f != nullptr);
  std::vector<std::string> out;
  char buf[4096];
  while (std::fgets(buf, sizeof(buf), f) != nullptr) {
    std::string line = buf;
    if (!line.empty() && line.back() == '\n') line.pop_back();
    out.push_back(line);
  }
  const int rc = pclose(f);
  REQUIRE(WIFEXITED(rc));
  REQUIRE(WEXITSTATUS(rc) == 0);
  return out;
}

// What TARGET (a custom target) directly stands for: the inputs `ninja -t query` lists.
std::set<std::string> deliverables_of(const std::string& target) {
  std::set<std::string> out;
  bool in_inputs = false;
  for (const std::string& line : ninja_tool("query", target)) {
    if (line.rfind("  input:", 0) == 0) in_inputs = true;
    else if (line.rfind("  outputs:", 0) == 0) in_inputs = false;
    else if (in_inputs && line.rfind("    ", 0) == 0) out.insert(line.substr(4));
  }
  return out;
}

// Whether anything TARGET is built from, recursively, is a test (test objects and
// executables live under tests/ in the build folder).
bool builds_a_test(const std::string& target) {
  for (const std::string& p : ninja_tool("inputs", target))
    if (p.rfind("tests/", 0) == 0) return true;
  return false;
}
}  // namespace

TEST_CASE("main-job: creased, creasectl and the plugins of config/sim.yaml, no test") {
  const auto inputs = deliverables_of("main-job");
  CHECK(inputs.count("bin/creased") == 1);
  CHECK(inputs.count("bin/creasectl") == 1);
  CHECK(inputs.count("plugins-lib/libcrease_test_counter_v2.so") == 1);  // the README's hot-swap
  crease::config::LoadOptions o;
  o.check_plugin_dirs_exist = false;
  const auto cfg = crease::config::load_daemon_config(CREASE_SOURCE_DIR "/config/sim.yaml", o);
  REQUIRE(cfg.plugins.size() > 5);
  for (const auto& p : cfg.plugins) {
    CAPTURE(p.library);
    CHECK(inputs.count("plugins-lib/lib" + p.library + ".so") == 1);
  }
  CHECK_FALSE(builds_a_test("main-job"));
  CHECK(builds_a_test("all"));  // the check sees tests where they are built
}

TEST_CASE("tools/run builds main-job, not everything") {
  std::ifstream f(CREASE_SOURCE_DIR "/tools/run");
  std::stringstream s;
  s << f.rdbuf();
  CHECK(s.str().find("--target main-job") != std::string::npos);
}
