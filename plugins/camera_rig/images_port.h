// The `images` port that a camera source plugin (camera_sim, camera_replay, camera_v4l2) writes
// and the `vision` plugin reads: a frame channel (core/frames), a port of kind `frames` bound
// with the rig's cameras, named and remapped like every port (`ports: {images: NAME}`; default
// name `images`). Both ends bind it here, so they agree on its name, its cameras and the checks.
// Its global name travels in every CameraFrames announcement (the `frames` port), so it must
// fit there. Non-RT (configure time).
#pragma once

#include <memory>
#include <vector>

#include "core/frames/frame_channel.h"
#include "core/port_binder.h"
#include "plugins/camera_rig/camera_model.h"

namespace crease::vision {

inline constexpr char kImagesPort[] = "images";

enum class ImagesEnd { writer, reader };

// The frame channel's cameras for these calibrations: names and sizes, in order.
[[nodiscard]] std::vector<crease::frames::CameraSpec> channel_specs(
    const std::vector<Camera>& cameras);

// Binds `images` with `cameras` (their calibrations' names and sizes, in order). Throws
// PortError when the other end has other cameras, ConfigError when the name does not fit
// CameraFrames::channel.
[[nodiscard]] std::shared_ptr<crease::frames::FrameChannel> bind_images(
    crease::PortBinder& ports, const std::vector<Camera>& cameras, ImagesEnd end);
// The same for any port of kind frames and any images (a depth source's: depth_camera.h).
[[nodiscard]] std::shared_ptr<crease::frames::FrameChannel> bind_image_specs(
    crease::PortBinder& ports, const char* port,
    const std::vector<crease::frames::CameraSpec>& images, ImagesEnd end);

}  // namespace crease::vision
