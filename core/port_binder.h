// What a plugin's configure() gets besides its parameters: the means to bind its ports and to
// declare parameters that may be tuned while it runs. One PortBinder per plugin instance,
// owned by the host. Non-RT (configure time) only.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/port.h"
#include "core/port_registry.h"
#include "rt/log_queue.h"

namespace crease {

// A latest output with the value the host writes when the plugin faults, stops or is deactivated.
struct SafeOutput {
  std::string port;
  rt::LatestChannel* channel = nullptr;
  std::vector<unsigned char> safe_value;  // payload bytes
};

// A parameter the plugin lets the host change while it runs (applied at a cycle boundary).
struct Tunable {
  std::string key;
  double* target = nullptr;  // inside the plugin object; written only by the loop thread
  double lo = 0.0;
  double hi = 0.0;
  double value = 0.0;        // the value last set (what `param get` answers)
};

class PortBinder {
 public:
  // `remap` maps the plugin's port names to global port names (the configuration's `ports:`).
  PortBinder(PortRegistry& registry, std::string instance, std::map<std::string, std::string> remap,
             detail::OutputFlags* flags, rt::RtLogQueue* log);

  // Binds a latest output, with the value to publish whenever the plugin is not running
  // normally (fault, deactivation, shutdown).
  template <PortPayload T>
  LatestOutput<T> latest_output(std::string_view port, const T& safe_value) {
    rt::LatestChannel* ch = add_latest_output(port, port_type_of<T>(), &safe_value);
    return LatestOutput<T>(ch, flags_);
  }
  template <PortPayload T>
  LatestInput<T> latest_input(std::string_view port) {
    return LatestInput<T>(registry_.bind_latest_reader(global_name(port), port_type_of<T>(), instance_));
  }
  template <PortPayload T>
  QueueOutput<T> queue_output(std::string_view port, std::size_t capacity = PortRegistry::kDefaultQueueCapacity) {
    return QueueOutput<T>(registry_.bind_queue_writer(global_name(port), port_type_of<T>(), instance_, capacity),
                          flags_);
  }
  template <PortPayload T>
  QueueInput<T> queue_input(std::string_view port, std::size_t capacity = PortRegistry::kDefaultQueueCapacity) {
    return QueueInput<T>(registry_.bind_queue_reader(global_name(port), port_type_of<T>(), instance_, capacity));
  }

  // Binds the writing or reading end of a frame channel (camera images, core/frames) with the
  // cameras of the plugin's rig, in set order: a port of kind `frames`, named and remapped like
  // every port. The channel lives as long as the host; the worker thread that writes or reads
  // it claims its end on the channel itself.
  std::shared_ptr<frames::FrameChannel> frames_output(std::string_view port,
                                                      const std::vector<frames::CameraSpec>& cameras);
  std::shared_ptr<frames::FrameChannel> frames_input(std::string_view port,
                                                     const std::vector<frames::CameraSpec>& cameras);

  // Declares a parameter that `param set` may change while the plugin runs. *value is written
  // between two updates, on the loop thread, after validate_param() accepted it and it lies in
  // [lo, hi]. The current *value is the initial one.
  void tunable(std::string_view key, double* value, double lo, double hi);

  // The port `port` (after remapping) as some instance already bound it, for a plugin whose
  // port types come from its configuration (a bridge); nullopt when nothing bound it yet.
  [[nodiscard]] std::optional<PortInfo> find(std::string_view port) const;

  [[nodiscard]] const std::string& instance() const noexcept { return instance_; }
  [[nodiscard]] rt::RtLogQueue* log_queue() const noexcept { return log_; }

  // Host side.
  [[nodiscard]] const std::vector<SafeOutput>& safe_outputs() const noexcept { return safe_outputs_; }
  [[nodiscard]] std::vector<Tunable>& tunables() noexcept { return tunables_; }
  [[nodiscard]] const std::vector<Tunable>& tunables() const noexcept { return tunables_; }
  // Remapped port names the plugin never bound (a typo in the configuration's `ports:`).
  [[nodiscard]] std::vector<std::string> unused_remaps() const;

 private:
  std::string global_name(std::string_view port);
  rt::LatestChannel* add_latest_output(std::string_view port, const PortType& type, const void* safe_value);

  PortRegistry& registry_;
  std::string instance_;
  std::map<std::string, std::string> remap_;
  std::vector<std::string> used_remaps_;
  detail::OutputFlags* flags_;
  rt::RtLogQueue* log_;
  std::vector<SafeOutput> safe_outputs_;
  std::vector<Tunable> tunables_;
};

}  // namespace crease
