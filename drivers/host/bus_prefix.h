// The prefix of a simulated robot's mocked CAN buses: its buses are `<prefix>-hand_r`,
// `<prefix>-hand_l`, ... (abstract AF_UNIX names, shared by every process of the machine).
//
//   bus_prefix: auto        "crease-sim-<pid>": the same in every plugin of one process (the
//                           sim_world or sim_devices instance and the drivers of one creased
//                           meet), another
//                           in the next creased, so two simulated robots run side by side
//                           (two daemons in one process would share it: give them fixed ones)
//   bus_prefix: crease-sim  a fixed name, for separate processes that must meet on the buses
//                           (crease-simdevice devices, a recorder); one robot per fixed name
//
// A fixed prefix is 1..kMaxBusPrefix characters of [A-Za-z0-9._-], not "auto" itself.
// Non-RT (configure time).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "core/params.h"

namespace crease::drivers {

inline constexpr std::string_view kAutoBusPrefix = "auto";
inline constexpr std::size_t kMaxBusPrefix = 64;  // leaves room for the bus in a socket name

// "crease-sim-<pid>" for this process; the same value on every call.
[[nodiscard]] std::string auto_bus_prefix();

// Empty when `prefix` is a valid fixed prefix or "auto", else the reason it is not.
[[nodiscard]] std::string bus_prefix_problem(std::string_view prefix);

// Reads the `bus_prefix` parameter and resolves "auto". Absent: `fallback`, resolved the same
// way (std::nullopt: no prefix). Throws ConfigError naming file, line and key on a bad value.
[[nodiscard]] std::optional<std::string> bus_prefix_from_params(const Params& p,
                                                                std::optional<std::string> fallback);

// "<prefix>-<bus>".
[[nodiscard]] std::string prefixed_bus(const std::string& prefix, std::string_view bus);

// Where a simulated robot's serial link (e.g. the right hand's tactile matrix) is found:
// "<dir>/<prefix>-<name>", dir $XDG_RUNTIME_DIR or else /tmp; the simulated device listens on a
// Unix socket there (sim_world) or puts a symlink to a pty's slave (sim_devices), the driver
// connects or opens it. NAME: 1..32 of [A-Za-z0-9._-].
[[nodiscard]] std::string simulated_link_path(const std::string& prefix, std::string_view name);
[[nodiscard]] bool valid_link_name(std::string_view name) noexcept;

}  // namespace crease::drivers
