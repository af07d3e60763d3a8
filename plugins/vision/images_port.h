// The `images` port that a camera source plugin (camera_sim, camera_replay, camera_v4l2) writes
// and the `vision` plugin reads: a frame channel (core/frames), a port of kind `frames` bound
// with the rig's cameras, named and remapped like every port (`ports: {images: NAME}`; default
// name `images`). Both ends bind it here, so they agree on its name and on the checks. Its
// global name travels in every CameraFrames announcement (the `frames` port), so it must fit
// there. Non-RT (configure time); header-only, compiled into each plugin.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "camera_worker.h"
#include "core/assert.h"
#include "core/port_binder.h"
#include "core/port_types/camera_frames.h"

namespace crease::vision {

inline constexpr char kImagesPort[] = "images";

enum class ImagesEnd { writer, reader };

// Binds `images` with `cameras` (their calibrations' names and sizes, in order). Throws
// PortError when the other end has other cameras, ConfigError when the name does not fit
// CameraFrames::channel.
[[nodiscard]] inline std::shared_ptr<crease::frames::FrameChannel> bind_images(
    crease::PortBinder& ports, const std::vector<Camera>& cameras, ImagesEnd end) {
  auto channel = end == ImagesEnd::writer ? ports.frames_output(kImagesPort, channel_specs(cameras))
                                          : ports.frames_input(kImagesPort, channel_specs(cameras));
  crease::require_input(
      channel->name().size() < crease::CameraFrames::kChannelNameCapacity,
      "ports.images: frame channel name '" + channel->name() + "' is longer than " +
          std::to_string(crease::CameraFrames::kChannelNameCapacity - 1) + " characters");
  return channel;
}

}  // namespace crease::vision
