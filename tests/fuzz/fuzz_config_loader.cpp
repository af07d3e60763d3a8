// libFuzzer target: the daemon's configuration loader (core/config) on any text, with its
// default bounds (1 MiB, 100,000 nodes with aliases expanded). Invariant: it returns a
// configuration or throws crease::ConfigError naming the file; nothing else escapes, nothing
// hangs (an alias bomb is refused from one linear pass), nothing crashes.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/config/daemon_config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  crease::config::LoadOptions options;
  options.check_plugin_dirs_exist = false;
  try {
    const crease::config::DaemonConfig c = crease::config::load_daemon_config_from_string(text, "fuzz.yaml", options);
    if (c.loops.empty()) __builtin_trap();  // a configuration has at least one loop
  } catch (const crease::ConfigError& e) {
    if (std::string(e.what()).rfind("fuzz.yaml", 0) != 0) __builtin_trap();
  }
  return 0;
}
