// The host's ports: named, typed, single-writer channels, created when first bound and kept for
// the life of the host (so a reader never outlives its channel, whatever is swapped or unloaded).
// Non-RT: binding happens at configure time; the channels themselves are used from RT threads.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/port.h"

namespace crease {

struct PortInfo {
  std::string name;
  PortKind kind = PortKind::latest;
  std::string type_name;
  std::uint32_t type_version = 0;
  std::size_t size = 0;
  std::size_t capacity = 0;      // queue only
  std::string writer;            // instance name; empty while unbound
  std::vector<std::string> readers;
  std::uint64_t sequence = 0;    // latest: writes so far
  std::uint64_t pushed = 0;      // queue: pushed so far
  std::uint64_t dropped = 0;     // queue: dropped (full)
};

class PortRegistry {
 public:
  static constexpr std::size_t kDefaultQueueCapacity = 256;

  PortRegistry() = default;
  PortRegistry(const PortRegistry&) = delete;
  PortRegistry& operator=(const PortRegistry&) = delete;

  // Each throws PortError naming both ends on a kind, type, version or size mismatch, a second
  // writer (another instance), or a second reader of a queue. Rebinding by the same instance name
  // (a new version during a hot-swap) is allowed.
  rt::LatestChannel* bind_latest_writer(const std::string& port, const PortType& type, const std::string& instance);
  const rt::LatestChannel* bind_latest_reader(const std::string& port, const PortType& type, const std::string& instance);
  rt::QueueChannel* bind_queue_writer(const std::string& port, const PortType& type, const std::string& instance,
                                      std::size_t capacity);
  rt::QueueChannel* bind_queue_reader(const std::string& port, const PortType& type, const std::string& instance,
                                      std::size_t capacity);

  // Forgets the instance's roles (unload). The channels stay.
  void release(const std::string& instance);

  // Non-RT observers: the daemon and tests read ports through these.
  [[nodiscard]] const rt::LatestChannel* find_latest(const std::string& port) const;
  [[nodiscard]] rt::QueueChannel* find_queue(const std::string& port) const;
  [[nodiscard]] std::vector<PortInfo> list() const;

 private:
  struct Port {
    PortInfo info;
    std::unique_ptr<rt::LatestChannel> latest;
    std::unique_ptr<rt::QueueChannel> queue;
  };
  Port& bind(const std::string& port, PortKind kind, const PortType& type, const std::string& instance, bool writer,
             std::size_t capacity);

  mutable std::mutex mu_;
  std::map<std::string, std::unique_ptr<Port>> ports_;
};

}  // namespace crease
