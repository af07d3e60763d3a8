// The JSON views of a running host that the control commands `status`, `loops`, `plugins`,
// `ports`, `threads` and `stats` answer with (field names are part of the control protocol: README.md).
// Non-RT; the counters are read as they are now (atomics, histogram snapshots).
#pragma once

#include <cstdint>

#include <nlohmann/json.hpp>

#include "core/control/control_server.h"
#include "core/daemon/report_builder.h"
#include "core/plugin_host.h"
#include "core/port_registry.h"

namespace crease::daemon {

// State, configuration, uptime since facts.start_ns (now_ns: CLOCK_MONOTONIC), counts (faults,
// device faults so far, instances whose device is in fault now), whether SCHED_FIFO and
// mlockall were applied, and with a SERVER its clients and the requests it refused:
// {"control": {"clients", "busy", "refused"}} (refused: malformed, unknown, bad arguments).
[[nodiscard]] nlohmann::json status_view(const PluginHost& host, const RunFacts& facts, std::int64_t now_ns,
                                         const control::ControlServer* server = nullptr);
// Per loop: spec, cycles, overruns, wake-up and execution percentiles (us).
[[nodiscard]] nlohmann::json loops_view(const PluginHost& host);
// Where the non-RT threads run (daemon.non_rt_cpus), and every thread of the daemon now: name,
// tid, CPUs (affinity), scheduling policy and priority.
[[nodiscard]] nlohmann::json threads_view(const RunFacts& facts);
// Per instance: plugin, library, state, health, counters (faults, device faults, cycles over
// its time budget, RT heap allocations), its firewall limits, execution p99 (us), tunables.
[[nodiscard]] nlohmann::json plugins_view(const PluginHost& host);
// Per port, every kind: name, kind, type, version, size, writer, readers, and the kind's
// counters (latest: writes; queue: capacity, pushed, dropped; frames: cameras, published,
// consumed, overwritten).
[[nodiscard]] nlohmann::json ports_view(const PortRegistry& ports);
// The control server's counters (null without a server), faults, device faults, RT heap
// allocations (whether counted, the total) and per instance (state, health, faults, device
// faults, cycles over budget, RT allocations), and loops_view().
[[nodiscard]] nlohmann::json stats_view(const PluginHost& host, const control::ControlServer* server);

}  // namespace crease::daemon
