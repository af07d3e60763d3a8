// The host's ports: named, typed, single-writer channels, created when first bound and kept for
// the life of the host (so a reader never outlives its channel, whatever is swapped or unloaded).
// Three kinds share one namespace of names: `latest` and `queue` carry payloads (core/port.h),
// `frames` carries camera images between two plugins' worker threads (core/frames).
// Non-RT: binding happens at configure time; the channels themselves are used from RT threads
// (latest, queue) or worker threads (frames).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/frames/frame_channel.h"
#include "core/port.h"

namespace crease {

struct PortInfo {
  std::string name;
  PortKind kind = PortKind::latest;
  std::string type_name;
  std::uint32_t type_version = 0;
  std::size_t size = 0;          // latest, queue: payload bytes; frames: pixels of one set
  std::size_t capacity = 0;      // queue only
  std::string writer;            // instance name; empty while unbound
  std::vector<std::string> readers;
  std::uint64_t sequence = 0;    // latest: writes so far; frames: sets published so far
  std::uint64_t pushed = 0;      // queue: pushed so far
  std::uint64_t dropped = 0;     // queue: dropped (full)
  std::vector<std::string> cameras;  // frames: "NAME WIDTHxHEIGHT" per camera, in set order
  std::uint64_t consumed = 0;        // frames: sequence of the newest set the reader took
  std::uint64_t overwritten = 0;     // frames: sets replaced before the reader took them
};

[[nodiscard]] const char* to_string(PortKind kind) noexcept;  // "latest", "queue", "frames"

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
  // A frame channel, created with `cameras` (its type) when first bound. Throws PortError as
  // above, naming the first camera that differs when the other end has other cameras (another
  // rig, another image size), and for a second reader (frame channels have one reader); throws
  // ConfigError when the cameras are invalid (FrameChannel's constructor). The workers of both
  // ends still claim their end on the channel (a hot swap's new worker waits for the old one).
  std::shared_ptr<frames::FrameChannel> bind_frames_writer(const std::string& port,
                                                           const std::vector<frames::CameraSpec>& cameras,
                                                           const std::string& instance);
  std::shared_ptr<frames::FrameChannel> bind_frames_reader(const std::string& port,
                                                           const std::vector<frames::CameraSpec>& cameras,
                                                           const std::string& instance);

  // Forgets the instance's roles (unload). The channels stay.
  void release(const std::string& instance);

  // Non-RT observers: the daemon and tests read ports through these.
  [[nodiscard]] const rt::LatestChannel* find_latest(const std::string& port) const;
  [[nodiscard]] rt::QueueChannel* find_queue(const std::string& port) const;
  [[nodiscard]] std::shared_ptr<const frames::FrameChannel> find_frames(const std::string& port) const;
  // Every port by name, with its counters as they are now.
  [[nodiscard]] std::vector<PortInfo> list() const;

 private:
  struct Port {
    PortInfo info;
    std::unique_ptr<rt::LatestChannel> latest;
    std::unique_ptr<rt::QueueChannel> queue;
    std::shared_ptr<frames::FrameChannel> frames;
  };
  Port& bind(const std::string& port, PortKind kind, const PortType& type, const std::string& instance, bool writer,
             std::size_t capacity);
  Port& bind_frames(const std::string& port, const std::vector<frames::CameraSpec>& cameras,
                    const std::string& instance, bool writer);
  // Finds or creates the port (create() fills the new one's info and channel), and checks
  // that it is of that kind.
  template <class Create>
  Port& find_or_create(const std::string& port, PortKind kind, const std::string& instance, bool writer,
                       Create&& create);
  // Records the instance as the port's writer or one of its readers (queues and frame
  // channels have one reader).
  static void take_role(Port& p, const std::string& instance, bool writer);

  mutable std::mutex mu_;
  std::map<std::string, std::unique_ptr<Port>> ports_;
};

}  // namespace crease
