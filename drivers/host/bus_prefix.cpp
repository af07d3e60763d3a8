#include "drivers/host/bus_prefix.h"

#include <unistd.h>

#include <cstdlib>

namespace crease::drivers {

std::string auto_bus_prefix() { return "crease-sim-" + std::to_string(::getpid()); }

std::string bus_prefix_problem(std::string_view prefix) {
  if (prefix.empty()) return "must not be empty (use 'auto' for one set of buses per daemon)";
  if (prefix == kAutoBusPrefix) return {};
  if (prefix.size() > kMaxBusPrefix) {
    return "at most " + std::to_string(kMaxBusPrefix) + " characters, got " + std::to_string(prefix.size());
  }
  for (const char c : prefix) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '_' || c == '-';
    if (!ok) return "'" + std::string(prefix) + "': only letters, digits, '.', '_' and '-', or 'auto'";
  }
  return {};
}

std::optional<std::string> bus_prefix_from_params(const Params& p, std::optional<std::string> fallback) {
  std::optional<std::string> prefix = std::move(fallback);
  if (p.has("bus_prefix")) prefix = p.get<std::string>("bus_prefix");
  if (!prefix) return std::nullopt;
  if (const std::string why = bus_prefix_problem(*prefix); !why.empty()) p.fail("bus_prefix", why);
  if (*prefix == kAutoBusPrefix) return auto_bus_prefix();
  return prefix;
}

std::string prefixed_bus(const std::string& prefix, std::string_view bus) {
  std::string full = prefix;
  full += '-';
  full += bus;
  return full;
}

bool valid_link_name(std::string_view name) noexcept {
  if (name.empty() || name.size() > 32) return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '_' || c == '-';
    if (!ok) return false;
  }
  return name != "." && name != "..";
}

std::string simulated_link_path(const std::string& prefix, std::string_view name) {
  const char* dir = std::getenv("XDG_RUNTIME_DIR");
  std::string path = dir != nullptr && dir[0] == '/' ? dir : "/tmp";
  path += '/';
  path += prefixed_bus(prefix, name);
  return path;
}

}  // namespace crease::drivers
