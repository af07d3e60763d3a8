#include "plugins/camera_rig/images_port.h"

#include <string>

#include "core/assert.h"
#include "core/port_types/camera_frames.h"

namespace crease::vision {

std::vector<crease::frames::CameraSpec> channel_specs(const std::vector<Camera>& cameras) {
  std::vector<crease::frames::CameraSpec> specs;
  for (const Camera& c : cameras) specs.push_back({c.name, c.width, c.height});
  return specs;
}

std::shared_ptr<crease::frames::FrameChannel> bind_images(crease::PortBinder& ports,
                                                          const std::vector<Camera>& cameras,
                                                          ImagesEnd end) {
  auto channel = end == ImagesEnd::writer ? ports.frames_output(kImagesPort, channel_specs(cameras))
                                          : ports.frames_input(kImagesPort, channel_specs(cameras));
  crease::require_input(
      channel->name().size() < crease::CameraFrames::kChannelNameCapacity,
      "ports.images: frame channel name '" + channel->name() + "' is longer than " +
          std::to_string(crease::CameraFrames::kChannelNameCapacity - 1) + " characters");
  return channel;
}

}  // namespace crease::vision
