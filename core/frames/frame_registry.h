// The process-wide registry of frame channels, by name. Camera source plugins and the vision
// plugin open the same channel at configure time, whatever order they configure in.
//
// One instance per process: it lives in the shared library crease_frames, which crease_core
// (hence creased) depends on, never in a plugin library (dlclose'd on a hot swap) and never as
// an inline function's static (every hidden-visibility plugin would get its own copy). Channels
// live until the process ends, so a pointer taken at configure time stays valid across hot
// swaps of either end.
// Non-RT: open/find take a mutex; call them at configure time only.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/frames/frame_channel.h"

namespace crease::frames {

class FrameRegistry {
 public:
  [[nodiscard]] static FrameRegistry& instance();

  // The channel `name`, created with `cameras` if it does not exist yet. Throws
  // std::invalid_argument naming the channel and the first camera that differs when it exists
  // with other cameras (another rig, another image size), or when the specs are invalid.
  [[nodiscard]] std::shared_ptr<FrameChannel> open(const std::string& name,
                                                   const std::vector<CameraSpec>& cameras);
  // nullptr when no channel has that name.
  [[nodiscard]] std::shared_ptr<FrameChannel> find(const std::string& name) const;

 private:
  FrameRegistry() = default;
  mutable std::mutex mu_;
  std::map<std::string, std::shared_ptr<FrameChannel>> channels_;
};

}  // namespace crease::frames
