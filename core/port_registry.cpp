#include "core/port_registry.h"

#include <algorithm>

#include "core/errors.h"

namespace crease {
namespace {
const char* kind_name(PortKind k) { return k == PortKind::latest ? "latest" : "queue"; }

std::string describe(const std::string& type, std::uint32_t version, std::size_t size) {
  return type + " v" + std::to_string(version) + " (" + std::to_string(size) + " bytes)";
}
}  // namespace

PortRegistry::Port& PortRegistry::bind(const std::string& port, PortKind kind, const PortType& type,
                                       const std::string& instance, bool writer, std::size_t capacity) {
  const std::string role = writer ? "writes" : "reads";
  auto it = ports_.find(port);
  if (it == ports_.end()) {
    auto p = std::make_unique<Port>();
    p->info.name = port;
    p->info.kind = kind;
    p->info.type_name = type.name;
    p->info.type_version = type.version;
    p->info.size = type.size;
    if (kind == PortKind::latest) {
      p->latest = std::make_unique<rt::LatestChannel>(type.size);
    } else {
      p->info.capacity = capacity == 0 ? kDefaultQueueCapacity : capacity;
      p->queue = std::make_unique<rt::QueueChannel>(type.size, p->info.capacity);
      p->info.capacity = p->queue->capacity();
    }
    it = ports_.emplace(port, std::move(p)).first;
  }
  Port& p = *it->second;
  const std::string other = !p.info.writer.empty() ? "instance '" + p.info.writer + "' writes"
                            : !p.info.readers.empty() ? "instance '" + p.info.readers.front() + "' reads"
                                                      : "it was created as";
  if (p.info.kind != kind) {
    throw PortError("port '" + port + "': instance '" + instance + "' " + role + " it as a " + kind_name(kind) +
                    " port, but " + other + " it as a " + kind_name(p.info.kind) + " port");
  }
  if (p.info.type_name != type.name || p.info.type_version != type.version || p.info.size != type.size) {
    throw PortError("port '" + port + "': instance '" + instance + "' " + role + " " +
                    describe(type.name, type.version, type.size) + ", but " + other + " " +
                    describe(p.info.type_name, p.info.type_version, p.info.size));
  }
  if (kind == PortKind::queue && capacity > p.info.capacity) {
    throw PortError("port '" + port + "': instance '" + instance + "' asks for a queue of " + std::to_string(capacity) +
                    " records, but " + other + " it with " + std::to_string(p.info.capacity));
  }
  if (writer) {
    if (!p.info.writer.empty() && p.info.writer != instance) {
      throw PortError("port '" + port + "': instance '" + instance + "' cannot write it: instance '" + p.info.writer +
                      "' already does (ports have a single writer)");
    }
    p.info.writer = instance;
  } else {
    auto& rs = p.info.readers;
    if (kind == PortKind::queue && !rs.empty() && rs.front() != instance) {
      throw PortError("port '" + port + "': instance '" + instance + "' cannot read it: instance '" + rs.front() +
                      "' already does (queues have a single reader)");
    }
    if (std::find(rs.begin(), rs.end(), instance) == rs.end()) rs.push_back(instance);
  }
  return p;
}

rt::LatestChannel* PortRegistry::bind_latest_writer(const std::string& port, const PortType& type,
                                                    const std::string& instance) {
  std::lock_guard lock(mu_);
  return bind(port, PortKind::latest, type, instance, true, 0).latest.get();
}

const rt::LatestChannel* PortRegistry::bind_latest_reader(const std::string& port, const PortType& type,
                                                          const std::string& instance) {
  std::lock_guard lock(mu_);
  return bind(port, PortKind::latest, type, instance, false, 0).latest.get();
}

rt::QueueChannel* PortRegistry::bind_queue_writer(const std::string& port, const PortType& type,
                                                  const std::string& instance, std::size_t capacity) {
  std::lock_guard lock(mu_);
  return bind(port, PortKind::queue, type, instance, true, capacity).queue.get();
}

rt::QueueChannel* PortRegistry::bind_queue_reader(const std::string& port, const PortType& type,
                                                  const std::string& instance, std::size_t capacity) {
  std::lock_guard lock(mu_);
  return bind(port, PortKind::queue, type, instance, false, capacity).queue.get();
}

void PortRegistry::release(const std::string& instance) {
  std::lock_guard lock(mu_);
  for (auto& [name, p] : ports_) {
    if (p->info.writer == instance) p->info.writer.clear();
    std::erase(p->info.readers, instance);
  }
}

const rt::LatestChannel* PortRegistry::find_latest(const std::string& port) const {
  std::lock_guard lock(mu_);
  auto it = ports_.find(port);
  return it == ports_.end() ? nullptr : it->second->latest.get();
}

rt::QueueChannel* PortRegistry::find_queue(const std::string& port) const {
  std::lock_guard lock(mu_);
  auto it = ports_.find(port);
  return it == ports_.end() ? nullptr : it->second->queue.get();
}

std::vector<PortInfo> PortRegistry::list() const {
  std::lock_guard lock(mu_);
  std::vector<PortInfo> out;
  for (const auto& [name, p] : ports_) {
    PortInfo i = p->info;
    if (p->latest) i.sequence = p->latest->sequence();
    if (p->queue) {
      i.pushed = p->queue->pushed();
      i.dropped = p->queue->dropped();
    }
    out.push_back(std::move(i));
  }
  return out;
}

}  // namespace crease
