#include "core/plugin_library.h"

#include <doctest/doctest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/errors.h"

namespace fs = std::filesystem;

namespace {
const fs::path kDir = CREASE_PLUGIN_DIR;

std::string error_of(auto&& fn) {
  try {
    fn();
  } catch (const crease::LoadError& e) {
    return e.what();
  }
  return "no error";
}

// A private copy of one plugin in a fresh directory, for permission tests.
struct TempPluginDir {
  fs::path dir;
  explicit TempPluginDir(const std::string& lib) {
    char tmpl[] = "/tmp/crease-plugins-XXXXXX";
    dir = mkdtemp(tmpl);
    ::chmod(dir.c_str(), 0755);
    fs::copy_file(kDir / ("lib" + lib + ".so"), dir / ("lib" + lib + ".so"));
    ::chmod((dir / ("lib" + lib + ".so")).c_str(), 0755);
  }
  ~TempPluginDir() { fs::remove_all(dir); }
};
}  // namespace

TEST_CASE("a good plugin loads and its descriptor is copied") {
  auto lib = crease::PluginLibrary::open("crease_test_counter_v1", {kDir});
  CHECK(lib->plugin_name() == "test_counter");
  CHECK(lib->plugin_version() == "1.0.0");
  CHECK(lib->descriptor().abi_version == CREASE_PLUGIN_ABI_VERSION);
}

TEST_CASE("each refusal names the file and the reason") {
  CHECK(error_of([] { crease::PluginLibrary::open("crease_test_wrong_abi", {kDir}); })
            .find("it was built for plugin ABI 99, this host speaks ABI 2") != std::string::npos);
  // A plugin of the ABI before the write phase: refused by its version, before its descriptor
  // (a shorter struct) is read any further.
  CHECK(error_of([] { crease::PluginLibrary::open("crease_test_abi_v1", {kDir}); })
            .find("it was built for plugin ABI 1, this host speaks ABI 2 (rebuild the plugin)") != std::string::npos);
  CHECK(error_of([] { crease::PluginLibrary::open("crease_test_no_entry", {kDir}); })
            .find("libcrease_test_no_entry.so' refused: it has no entry point 'crease_plugin_entry'") != std::string::npos);
  CHECK(error_of([] { crease::PluginLibrary::open("does_not_exist", {kDir}); })
            .find("'does_not_exist' refused: not found as libdoes_not_exist.so") != std::string::npos);
  CHECK(error_of([] { crease::PluginLibrary::open("/usr/lib/x86_64-linux-gnu/libm.so.6", {kDir}); })
            .find("it is outside the configured plugin directories") != std::string::npos);
  CHECK(error_of([] { crease::PluginLibrary::open((kDir / ".." / "plugins-lib" / ".." / "rt" / "libcrease_rt.so").string(), {kDir}); })
            .find("outside the configured plugin directories") != std::string::npos);
  CHECK(error_of([] { crease::PluginLibrary::open("x", {}); }).find("no plugin directories are configured") !=
        std::string::npos);
}

TEST_CASE("files and directories writable by group or others are refused") {
  TempPluginDir t("crease_test_counter_v1");
  CHECK(error_of([&] { crease::PluginLibrary::open("crease_test_counter_v1", {t.dir}); }) == "no error");
  ::chmod((t.dir / "libcrease_test_counter_v1.so").c_str(), 0775);
  CHECK(error_of([&] { crease::PluginLibrary::open("crease_test_counter_v1", {t.dir}); })
            .find("refused: it is writable by group or others") != std::string::npos);
  ::chmod((t.dir / "libcrease_test_counter_v1.so").c_str(), 0755);
  ::chmod(t.dir.c_str(), 0777);
  CHECK(error_of([&] { crease::PluginLibrary::open("crease_test_counter_v1", {t.dir}); })
            .find("plugin directory '" + t.dir.string() + "' refused: it is writable by group or others") != std::string::npos);
}

TEST_CASE("a file that is not a library is refused with dlopen's reason") {
  TempPluginDir t("crease_test_counter_v1");
  { std::ofstream(t.dir / "libgarbage.so") << "not an ELF file"; }
  ::chmod((t.dir / "libgarbage.so").c_str(), 0644);
  CHECK(error_of([&] { crease::PluginLibrary::open("garbage", {t.dir}); }).find("dlopen failed") != std::string::npos);
}
