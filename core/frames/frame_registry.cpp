#include "core/frames/frame_registry.h"

#include <stdexcept>

namespace crease::frames {

namespace {
std::string describe(const CameraSpec& c) {
  return "'" + c.name + "' " + std::to_string(c.width) + "x" + std::to_string(c.height);
}
}  // namespace

FrameRegistry& FrameRegistry::instance() {
  static FrameRegistry r;  // out of line on purpose: one per process (see the header)
  return r;
}

std::shared_ptr<FrameChannel> FrameRegistry::open(const std::string& name,
                                                  const std::vector<CameraSpec>& cameras) {
  std::lock_guard lock(mu_);
  auto it = channels_.find(name);
  if (it == channels_.end()) {
    auto ch = std::make_shared<FrameChannel>(name, cameras);
    channels_.emplace(name, ch);
    return ch;
  }
  const auto& have = it->second->cameras();
  if (have.size() != cameras.size())
    throw std::invalid_argument("frame channel '" + name + "' has " + std::to_string(have.size()) +
                                " cameras, asked for " + std::to_string(cameras.size()));
  for (std::size_t k = 0; k < have.size(); ++k) {
    if (!(have[k] == cameras[k]))
      throw std::invalid_argument("frame channel '" + name + "': camera " + std::to_string(k) +
                                  " is " + describe(have[k]) + ", asked for " +
                                  describe(cameras[k]));
  }
  return it->second;
}

std::shared_ptr<FrameChannel> FrameRegistry::find(const std::string& name) const {
  std::lock_guard lock(mu_);
  auto it = channels_.find(name);
  return it == channels_.end() ? nullptr : it->second;
}

}  // namespace crease::frames
