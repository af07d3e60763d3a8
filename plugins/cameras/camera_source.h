// Camera sources: N synchronised grey images per frame from live V4L2 devices (a recorded
// directory: replay_source.h; the simulated cameras' source, SimSource, is the simulated world's:
// plugins/sim_world/scene/sim_source.h), and a recorder writing the replay layout:
//   DIR/camK.yaml            calibration of camera K (plugins/camera_rig/camera_model.h format)
//   DIR/camK/NNNNNN.png      frame NNNNNN of camera K (8-bit grey)
//   DIR/timestamps.csv       "frame,timestamp_ns" header, one line per frame (integer ns)
// and of an RGB-D source (plugins/camera_rig/depth_camera.h) the same, with:
//   DIR/camK.yaml            its calibration with `depth_unit_mm` (what marks a depth recording)
//   DIR/camK/NNNNNN.png      its depth (16-bit PNG, counts of depth_unit_mm, 0 = no depth)
//   DIR/camK/NNNNNN.colour.png  its registered colour image (8-bit BGR)
// and of a camera the robot carries (its calibration with the mount keys of
// plugins/camera_rig/camera_mount.h, its rotation / translation relative to the mount shape):
//   DIR/camK/poses.csv       the header `frame,r00,r01,r02,r10,r11,r12,r20,r21,r22,x_mm,y_mm,z_mm`,
//                            then per frame it delivered `INDEX,` and its world-from-camera pose
//                            at that capture (core/frames/frame_channel.h's CameraPose: rotation
//                            row by row, the camera's centre in mm), each number printed %.17g so
//                            that it reads back bit-identical
// A camera that delivers nothing this frame leaves its image empty; the others go on.
// Not RT code (file and device I/O, OpenCV allocation): run it on a vision worker thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/frames/frame_channel.h"
#include "plugins/camera_rig/camera_model.h"
#include "plugins/camera_rig/camera_mount.h"
#include "plugins/camera_rig/images_port.h"

namespace crease::vision {

struct Frame {
  std::int64_t timestamp_ns = 0;
  std::uint64_t index = 0;
  // One per image of the source's channel_images(): CV_8UC1 for the colour cameras (one image
  // per camera); a depth source's CV_16UC1 depth and CV_8UC3 colour. Empty = nothing delivered.
  std::vector<cv::Mat> images;
  // Set by the caller: images[k] are buffers of the right size to write into (a frame channel's
  // set); a source that can fill them in place does (SimSource), instead of fresh buffers.
  bool fill_in_place = false;
  // One per image (as images) where the source's cameras move: each image's camera pose at this
  // capture. Empty: every camera fixed (its calibration says where).
  std::vector<crease::frames::CameraPose> poses;
};

class CameraSource {
 public:
  virtual ~CameraSource() = default;
  [[nodiscard]] virtual const std::vector<Camera>& cameras() const = 0;
  // The images of one frame, in channel order: one 8-bit grey image per camera unless the
  // source says otherwise (an RGB-D source: plugins/camera_rig/depth_camera.h).
  [[nodiscard]] virtual std::vector<crease::frames::CameraSpec> channel_images() const {
    return channel_specs(cameras());
  }
  // An RGB-D source's depth unit per camera (mm per count); empty for grey cameras.
  [[nodiscard]] virtual std::vector<double> depth_units_mm() const { return {}; }
  // Per camera, the mount of one the robot carries (plugins/camera_rig/camera_mount.h; its
  // calibration is relative to it); empty or nullopt: fixed.
  [[nodiscard]] virtual std::vector<std::optional<CameraMount>> mounts() const { return {}; }
  // Fills the next frame; false at the end of a recording (or when no camera delivers).
  virtual bool grab(Frame& frame) = 0;
  // Any thread: asks a grab() that waits (a replay pacing its frames) to return soon, and every
  // later grab() to return false. The worker calls it before it stops.
  virtual void cancel() noexcept {}
};

// DIR/camK/NNNNNN.png: where the replay layout keeps frame `index` of camera `cam`.
[[nodiscard]] std::string replay_frame_path(const std::string& dir, std::size_t cam, std::uint64_t index);
// DIR/camK/NNNNNN.colour.png: the colour image of a depth recording's frame.
[[nodiscard]] std::string replay_colour_path(const std::string& dir, std::size_t cam,
                                             std::uint64_t index);
// DIR/camK/poses.csv: a carried camera's pose per frame, and that file's header.
[[nodiscard]] std::string replay_poses_path(const std::string& dir, std::size_t cam);
inline constexpr char kReplayPosesHeader[] =
    "frame,r00,r01,r02,r10,r11,r12,r20,r21,r22,x_mm,y_mm,z_mm";

// How a live camera that did not open, or stopped delivering, is brought back: the capture
// worker (inside grab()) retries opening it `initial_s` after the failure, doubling the wait
// after each failed attempt up to `max_s` (seconds, CLOCK_MONOTONIC).
struct ReconnectPolicy {
  double initial_s = 0.5;
  double max_s = 5.0;
};

// One live camera's retry clock under a ReconnectPolicy (the capture worker's).
struct ReconnectClock {
  std::int64_t retry_at_ns = 0;  // next open attempt while closed
  double backoff_s = 0;          // wait after the next failed attempt
  // Closed at NOW_NS: the first attempt initial_s later.
  void went_dark(const ReconnectPolicy& p, std::int64_t now_ns) noexcept;
  [[nodiscard]] bool due(std::int64_t now_ns) const noexcept { return now_ns >= retry_at_ns; }
  // The attempt at NOW_NS failed: the next one the current wait later, the wait then doubled
  // up to max_s.
  void failed_again(const ReconnectPolicy& p, std::int64_t now_ns) noexcept;
};

// Opens PATH into CAP: /dev/... through V4L2, asking for WIDTH x HEIGHT; an image sequence
// pattern (dir/%06d.png) through OpenCV's image reader, which reads each file when grabbed (a
// missing file: the camera stopped); anything else (a video file) through whichever backend
// opens it. False when it did not open (an OpenCV exception included).
bool open_capture(cv::VideoCapture& cap, const std::string& path, int width, int height);

// Live cameras through cv::VideoCapture; device k is cameras[k]. /dev/... opens with the V4L2
// backend; an image sequence pattern (dir/%06d.png) with OpenCV's image reader (a file missing
// when its turn comes is a camera that stopped); any other string (a video file) with whichever
// backend OpenCV finds. A device that does not open or stops (grab/retrieve fails) is released and
// reopened per the ReconnectPolicy; while it is dark, and when it delivers another image size,
// its image is empty (the others go on). grab() never ends. A reopen attempt runs inside grab()
// (a missing device fails at once; a device that came back delays that one frame by its open).
class V4l2Source final : public CameraSource {
 public:
  static constexpr std::size_t kMaxCameras = 32;  // one bit each in dark_mask()
  // Throws crease::ConfigError when devices and calibrations differ in number, there are more
  // than kMaxCameras, or the policy is not 0 < initial_s <= max_s.
  V4l2Source(std::vector<Camera> cameras, const std::vector<std::string>& devices,
             ReconnectPolicy policy = {});
  [[nodiscard]] const std::vector<Camera>& cameras() const override { return cameras_; }
  bool grab(Frame& frame) override;
  // The devices that did not open at construction.
  [[nodiscard]] const std::vector<std::string>& failed_devices() const { return failed_; }
  // Any thread (atomics). Bit k: camera k delivered nothing in the last grab (dark since
  // construction until the first grab when it did not open).
  [[nodiscard]] std::uint32_t dark_mask() const noexcept {
    return dark_.load(std::memory_order_acquire);
  }
  // Any thread. Times camera k (or all cameras) opened again after failing to open or stopping.
  [[nodiscard]] std::uint64_t reconnects(std::size_t k) const noexcept {
    return k < cameras_.size() ? reconnects_[k].load(std::memory_order_acquire) : 0;
  }
  [[nodiscard]] std::uint64_t reconnects() const noexcept {
    return total_reconnects_.load(std::memory_order_acquire);
  }

 private:
  struct Device {
    std::string path;
    cv::VideoCapture cap;
    bool open = false;
    ReconnectClock retry;
  };
  bool try_open(std::size_t k);                   // true when it opened
  void went_dark(std::size_t k, std::int64_t now_ns);  // release, retry after initial_s

  std::vector<Camera> cameras_;
  ReconnectPolicy policy_;
  std::vector<Device> devices_;
  std::vector<std::string> failed_;
  std::unique_ptr<std::atomic<std::uint64_t>[]> reconnects_;
  std::atomic<std::uint64_t> total_reconnects_{0};
  std::atomic<std::uint32_t> dark_{0};
  std::uint64_t next_ = 0;
};

// Writes frames in the replay layout (the `record` option of every source).
class Recorder {
 public:
  // depth_units_mm empty: grey cameras; else one per camera: an RGB-D source's layout. mounts:
  // per camera (or empty) the mount of a carried camera: its calibration is saved with the mount
  // keys and its pose per frame (Frame::poses) in camK/poses.csv (an RGB-D source's only).
  Recorder(const std::string& dir, const std::vector<Camera>& cameras,
           const std::vector<double>& depth_units_mm = {},
           const std::vector<std::optional<CameraMount>>& mounts = {});
  void write(const Frame& frame);

 private:
  std::string dir_;
  std::size_t ncam_;
  bool depth_ = false;
  std::FILE* stamps_ = nullptr;
  std::vector<std::FILE*> poses_;  // per camera: its poses.csv, nullptr when fixed

 public:
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;
};

}  // namespace crease::vision
