// Live RGB-D cameras (plugin camera_depth_v4l2): per camera its depth node, a V4L2 Z16 stream
// (v4l2_z16_device.h), and the node of the colour image registered to that depth (same size,
// same optics: a D405's colour comes from its left imager, which the depth is computed for),
// read through cv::VideoCapture as 8-bit BGR (outside /dev: an image sequence pattern, as
// camera_v4l2's). Each grab(): every open camera's next depth image (waiting up to wait_ms for
// it) and its newest colour image, into the RGB-D channel's images (depth at 2k, colour at 2k + 1,
// depth_camera.h), stamped with the first delivered depth image's capture time (the driver's,
// CLOCK_MONOTONIC for UVC devices).
// A camera whose depth or colour node does not open, stops or fails is closed (both nodes) and
// reopened per the ReconnectPolicy (as V4l2Source); while it is dark its images are empty and the
// others go on. A depth image skipped by the driver (flagged, short), a colour image of another
// size than the calibration's, or no depth within wait_ms leave that camera's images empty for
// the frame (counted), without closing it.
// Cameras the robot carries are refused (a ConfigError): their pose at each capture would come
// from the arm's joints at that time, which no live source reads yet.
// Not RT code (system calls, OpenCV): the capture worker's thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "plugins/camera_rig/depth_camera.h"
#include "plugins/cameras/camera_source.h"
#include "plugins/cameras/v4l2_z16_device.h"

namespace crease::vision {

class V4l2DepthSource final : public CameraSource {
 public:
  static constexpr std::size_t kMaxCameras = 16;  // 32 images a set (depth_tracking's limit)
  // Throws crease::ConfigError when the devices and calibrations differ in number, a calibration
  // has a mount, there are more than kMaxCameras, wait_ms is not in 1..1000 or the policy is not
  // 0 < initial_s <= max_s. IO: the depth nodes' system calls (tests emulate a node).
  V4l2DepthSource(std::vector<DepthCamera> cameras, const std::vector<std::string>& depth_devices,
                  const std::vector<std::string>& colour_devices, ReconnectPolicy policy = {},
                  int wait_ms = 100, V4l2Io& io = system_v4l2_io());

  [[nodiscard]] const std::vector<Camera>& cameras() const override { return cameras_; }
  [[nodiscard]] std::vector<crease::frames::CameraSpec> channel_images() const override {
    return depth_channel_specs(cameras_);
  }
  [[nodiscard]] std::vector<double> depth_units_mm() const override { return units_; }
  bool grab(Frame& frame) override;
  void cancel() noexcept override { cancelled_.store(true, std::memory_order_release); }

  // The cameras whose nodes did not open at construction, with why.
  [[nodiscard]] const std::vector<std::string>& failed() const { return failed_; }
  // Any thread (atomics). Bit k: camera k delivered nothing in the last grab.
  [[nodiscard]] std::uint32_t dark_mask() const noexcept {
    return dark_.load(std::memory_order_acquire);
  }
  // Any thread: times a camera opened again after failing; depth images the drivers skipped or
  // that did not come within wait_ms; colour images of another size than the calibration's.
  [[nodiscard]] std::uint64_t reconnects() const noexcept {
    return reconnects_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::uint64_t missed_depth() const noexcept {
    return missed_depth_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::uint64_t wrong_colour() const noexcept {
    return wrong_colour_.load(std::memory_order_acquire);
  }

 private:
  struct Node {
    std::string depth_path, colour_path;
    std::unique_ptr<V4l2Z16Device> depth;
    cv::VideoCapture colour;
    bool open = false;
    ReconnectClock retry;
  };
  std::string try_open(std::size_t k);  // empty when both nodes opened
  void went_dark(std::size_t k, std::int64_t now_ns);

  std::vector<Camera> cameras_;
  std::vector<double> units_;
  ReconnectPolicy policy_;
  int wait_ms_;
  std::vector<Node> nodes_;
  std::vector<std::string> failed_;
  std::atomic<bool> cancelled_{false};
  std::atomic<std::uint32_t> dark_{0};
  std::atomic<std::uint64_t> reconnects_{0}, missed_depth_{0}, wrong_colour_{0};
  std::uint64_t next_ = 0;
};

}  // namespace crease::vision
