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
  return bind_image_specs(ports, kImagesPort, channel_specs(cameras), end);
}

std::shared_ptr<crease::frames::FrameChannel> bind_image_specs(
    crease::PortBinder& ports, const char* port,
    const std::vector<crease::frames::CameraSpec>& images, ImagesEnd end) {
  auto channel = end == ImagesEnd::writer ? ports.frames_output(port, images)
                                          : ports.frames_input(port, images);
  crease::require_input(
      channel->name().size() < crease::CameraFrames::kChannelNameCapacity,
      std::string("ports.") + port + ": frame channel name '" + channel->name() + "' is longer than " +
          std::to_string(crease::CameraFrames::kChannelNameCapacity - 1) + " characters");
  return channel;
}

}  // namespace crease::vision
