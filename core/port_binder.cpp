#include "core/port_binder.h"

#include <algorithm>
#include <cstring>

#include "core/assert.h"

namespace crease {

PortBinder::PortBinder(PortRegistry& registry, std::string instance, std::map<std::string, std::string> remap,
                       detail::OutputFlags* flags, rt::RtLogQueue* log)
    : registry_(registry), instance_(std::move(instance)), remap_(std::move(remap)), flags_(flags), log_(log) {}

std::string PortBinder::global_name(std::string_view port) {
  const std::string local(port);
  auto it = remap_.find(local);
  if (it == remap_.end()) return local;
  used_remaps_.push_back(local);
  return it->second;
}

rt::LatestChannel* PortBinder::add_latest_output(std::string_view port, const PortType& type, const void* safe_value) {
  const std::string global = global_name(port);
  rt::LatestChannel* ch = registry_.bind_latest_writer(global, type, instance_);
  SafeOutput out{global, ch, std::vector<unsigned char>(type.size)};
  std::memcpy(out.safe_value.data(), safe_value, type.size);
  safe_outputs_.push_back(std::move(out));
  return ch;
}

std::optional<PortInfo> PortBinder::find(std::string_view port) const {
  const auto it = remap_.find(std::string(port));
  const std::string global = it == remap_.end() ? std::string(port) : it->second;
  for (PortInfo& info : registry_.list()) {
    if (info.name == global) return std::move(info);
  }
  return std::nullopt;
}

std::shared_ptr<frames::FrameChannel> PortBinder::frames_output(std::string_view port,
                                                                const std::vector<frames::CameraSpec>& cameras) {
  return registry_.bind_frames_writer(global_name(port), cameras, instance_);
}

std::shared_ptr<frames::FrameChannel> PortBinder::frames_input(std::string_view port,
                                                               const std::vector<frames::CameraSpec>& cameras) {
  return registry_.bind_frames_reader(global_name(port), cameras, instance_);
}

void PortBinder::tunable(std::string_view key, double* value, double lo, double hi) {
  const std::string k(key);
  // What a plugin library declares is input to the host: refused, never a crash of creased.
  require_input(value != nullptr && lo <= hi,
                "instance '" + instance_ + "': tunable '" + k + "' needs a target and lo <= hi");
  for (const Tunable& t : tunables_) {
    require_input(t.key != k, "instance '" + instance_ + "': tunable '" + k + "' declared twice");
  }
  tunables_.push_back(Tunable{k, value, lo, hi, *value});
}

std::vector<std::string> PortBinder::unused_remaps() const {
  std::vector<std::string> out;
  for (const auto& [local, global] : remap_) {
    if (std::find(used_remaps_.begin(), used_remaps_.end(), local) == used_remaps_.end()) out.push_back(local);
  }
  return out;
}

}  // namespace crease
