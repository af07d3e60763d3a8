#include "core/port_registry.h"

#include <algorithm>

#include "core/assert.h"
#include "core/errors.h"

namespace crease {
namespace {
std::string describe(const std::string& type, std::uint32_t version, std::size_t size) {
  return type + " v" + std::to_string(version) + " (" + std::to_string(size) + " bytes)";
}

std::string describe(const frames::CameraSpec& c) {
  return "'" + c.name + "' " + std::to_string(c.width) + "x" + std::to_string(c.height) +
         (c.bytes_per_pixel == 1 ? "" : "x" + std::to_string(c.bytes_per_pixel) + " bytes");
}

const char* role_of(bool writer) { return writer ? "writes" : "reads"; }

// The port's existing end, for messages: "instance 'x' writes", ... or "it was created as".
std::string other_end(const PortInfo& i) {
  return !i.writer.empty()    ? "instance '" + i.writer + "' writes"
         : !i.readers.empty() ? "instance '" + i.readers.front() + "' reads"
                              : "it was created as";
}
}  // namespace

const char* to_string(PortKind kind) noexcept {
  switch (kind) {
    case PortKind::latest: return "latest";
    case PortKind::queue: return "queue";
    case PortKind::frames: return "frames";
  }
  return "?";
}

template <class Create>
PortRegistry::Port& PortRegistry::find_or_create(const std::string& port, PortKind kind, const std::string& instance,
                                                 bool writer, Create&& create) {
  auto it = ports_.find(port);
  if (it == ports_.end()) {
    auto p = std::make_unique<Port>();
    p->info.name = port;
    p->info.kind = kind;
    create(*p);
    it = ports_.emplace(port, std::move(p)).first;
  }
  Port& p = *it->second;
  if (p.info.kind != kind) {
    throw PortError("port '" + port + "': instance '" + instance + "' " + role_of(writer) + " it as a " +
                    to_string(kind) + " port, but " + other_end(p.info) + " it as a " + to_string(p.info.kind) +
                    " port");
  }
  return p;
}

void PortRegistry::take_role(Port& p, const std::string& instance, bool writer) {
  const std::string& port = p.info.name;
  if (writer) {
    if (!p.info.writer.empty() && p.info.writer != instance) {
      throw PortError("port '" + port + "': instance '" + instance + "' cannot write it: instance '" + p.info.writer +
                      "' already does (ports have a single writer)");
    }
    p.info.writer = instance;
    return;
  }
  auto& rs = p.info.readers;
  if (p.info.kind != PortKind::latest && !rs.empty() && rs.front() != instance) {
    throw PortError("port '" + port + "': instance '" + instance + "' cannot read it: instance '" + rs.front() +
                    "' already does (" + (p.info.kind == PortKind::queue ? "queues" : "frame channels") +
                    " have a single reader)");
  }
  if (std::find(rs.begin(), rs.end(), instance) == rs.end()) rs.push_back(instance);
}

PortRegistry::Port& PortRegistry::bind(const std::string& port, PortKind kind, const PortType& type,
                                       const std::string& instance, bool writer, std::size_t capacity) {
  Port& p = find_or_create(port, kind, instance, writer, [&](Port& n) {
    n.info.type_name = type.name;
    n.info.type_version = type.version;
    n.info.size = type.size;
    if (kind == PortKind::latest) {
      n.latest = std::make_unique<rt::LatestChannel>(type.size);
    } else {
      n.queue = std::make_unique<rt::QueueChannel>(type.size, capacity == 0 ? kDefaultQueueCapacity : capacity);
      n.info.capacity = n.queue->capacity();
    }
  });
  if (p.info.type_name != type.name || p.info.type_version != type.version || p.info.size != type.size) {
    throw PortError("port '" + port + "': instance '" + instance + "' " + role_of(writer) + " " +
                    describe(type.name, type.version, type.size) + ", but " + other_end(p.info) + " " +
                    describe(p.info.type_name, p.info.type_version, p.info.size));
  }
  if (kind == PortKind::queue && capacity > p.info.capacity) {
    throw PortError("port '" + port + "': instance '" + instance + "' asks for a queue of " + std::to_string(capacity) +
                    " records, but " + other_end(p.info) + " it with " + std::to_string(p.info.capacity));
  }
  take_role(p, instance, writer);
  return p;
}

PortRegistry::Port& PortRegistry::bind_frames(const std::string& port, const std::vector<frames::CameraSpec>& cameras,
                                              const std::string& instance, bool writer) {
  // Checked before anything is created: a bad rig leaves no port behind.
  auto channel = ports_.count(port) ? nullptr : std::make_shared<frames::FrameChannel>(port, cameras);
  Port& p = find_or_create(port, PortKind::frames, instance, writer, [&](Port& n) {
    n.frames = std::move(channel);
    n.info.type_name = frames::FrameChannel::kTypeName;
    n.info.type_version = frames::FrameChannel::kTypeVersion;
    n.info.size = n.frames->set_bytes();
    for (const frames::CameraSpec& c : cameras) {
      n.info.cameras.push_back(c.name + " " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                               (c.bytes_per_pixel == 1 ? "" : "x" + std::to_string(c.bytes_per_pixel)));
    }
  });
  CREASE_DEMAND(p.frames != nullptr, "a port of kind frames always has its channel");
  const auto& have = p.frames->cameras();
  const std::string head = "port '" + port + "': instance '" + instance + "' " + role_of(writer) + " ";
  if (have.size() != cameras.size()) {
    throw PortError(head + std::to_string(cameras.size()) + " cameras, but " + other_end(p.info) + " " +
                    std::to_string(have.size()));
  }
  for (std::size_t k = 0; k < have.size(); ++k) {
    if (!(have[k] == cameras[k])) {
      throw PortError(head + "camera " + std::to_string(k) + " as " + describe(cameras[k]) + ", but " +
                      other_end(p.info) + " it as " + describe(have[k]));
    }
  }
  take_role(p, instance, writer);
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

std::shared_ptr<frames::FrameChannel> PortRegistry::bind_frames_writer(const std::string& port,
                                                                       const std::vector<frames::CameraSpec>& cameras,
                                                                       const std::string& instance) {
  std::lock_guard lock(mu_);
  return bind_frames(port, cameras, instance, true).frames;
}

std::shared_ptr<frames::FrameChannel> PortRegistry::bind_frames_reader(const std::string& port,
                                                                       const std::vector<frames::CameraSpec>& cameras,
                                                                       const std::string& instance) {
  std::lock_guard lock(mu_);
  return bind_frames(port, cameras, instance, false).frames;
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

std::shared_ptr<const frames::FrameChannel> PortRegistry::find_frames(const std::string& port) const {
  std::lock_guard lock(mu_);
  auto it = ports_.find(port);
  return it == ports_.end() ? nullptr : it->second->frames;
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
    if (p->frames) {
      i.sequence = p->frames->published();
      i.consumed = p->frames->consumed();
      i.overwritten = p->frames->overwritten();
    }
    out.push_back(std::move(i));
  }
  return out;
}

}  // namespace crease
