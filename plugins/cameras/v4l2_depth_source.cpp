#include "plugins/cameras/v4l2_depth_source.h"

#include "core/assert.h"
#include "core/errors.h"
#include "rt/clock.h"

namespace crease::vision {

V4l2DepthSource::V4l2DepthSource(std::vector<DepthCamera> cameras,
                                 const std::vector<std::string>& depth_devices,
                                 const std::vector<std::string>& colour_devices,
                                 ReconnectPolicy policy, int wait_ms, V4l2Io& io)
    : policy_(policy), wait_ms_(wait_ms) {
  const std::string n = std::to_string(cameras.size());
  crease::require_input(depth_devices.size() == cameras.size(),
                        "camera_depth_v4l2: " + std::to_string(depth_devices.size()) +
                            " depth devices for " + n + " calibrations");
  crease::require_input(colour_devices.size() == cameras.size(),
                        "camera_depth_v4l2: " + std::to_string(colour_devices.size()) +
                            " colour devices for " + n + " calibrations");
  crease::require_input(
      cameras.size() <= kMaxCameras,
      "camera_depth_v4l2: " + n + " cameras, at most " + std::to_string(kMaxCameras));
  crease::require_input(wait_ms >= 1 && wait_ms <= 1000,
                        "camera_depth_v4l2: wait_ms must be within 1..1000");
  crease::require_input(policy_.initial_s > 0.0 && policy_.max_s >= policy_.initial_s,
                        "camera_depth_v4l2: reconnect times must satisfy 0 < initial <= max");
  for (std::size_t k = 0; k < cameras.size(); ++k)
    crease::require_input(
        !cameras[k].mount.has_value(),
        "camera_depth_v4l2: camera " + std::to_string(k) + " (" + cameras[k].camera.name +
            ") is carried by the robot (mount keys): its pose at each capture is not "
            "read live yet; calibrate it as a fixed camera");
  for (const DepthCamera& c : cameras) {
    cameras_.push_back(c.camera);
    units_.push_back(c.depth_unit_mm);
  }
  nodes_.resize(cameras.size());
  const std::int64_t now = crease::rt::now_ns();
  std::uint32_t dark = 0;
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    nodes_[k].depth_path = depth_devices[k];
    nodes_[k].colour_path = colour_devices[k];
    nodes_[k].depth = std::make_unique<V4l2Z16Device>(io);
    const std::string why = try_open(k);
    if (why.empty()) continue;
    failed_.push_back(why);
    dark |= 1u << k;
    went_dark(k, now);
  }
  dark_.store(dark, std::memory_order_release);
}

std::string V4l2DepthSource::try_open(std::size_t k) {
  Node& d = nodes_[k];
  const Camera& c = cameras_[k];
  V4l2Z16Device::Config cfg;
  cfg.path = d.depth_path;
  cfg.width = c.width;
  cfg.height = c.height;
  std::string why = d.depth->open(cfg);
  if (why.empty() && !open_capture(d.colour, d.colour_path, c.width, c.height))
    why = d.colour_path + ": does not open";
  d.open = why.empty();
  if (!d.open) {
    d.depth->close();
    d.colour.release();
  }
  return why;
}

void V4l2DepthSource::went_dark(std::size_t k, std::int64_t now_ns) {
  Node& d = nodes_[k];
  d.depth->close();
  d.colour.release();
  d.open = false;
  d.retry.went_dark(policy_, now_ns);
}

bool V4l2DepthSource::grab(Frame& frame) {
  if (cancelled_.load(std::memory_order_acquire)) return false;
  frame.index = next_++;
  frame.images.resize(2 * nodes_.size());
  frame.poses.clear();
  const std::int64_t before = crease::rt::now_ns();
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    Node& d = nodes_[k];
    if (d.open || !d.retry.due(before)) continue;
    if (try_open(k).empty()) {
      reconnects_.fetch_add(1, std::memory_order_acq_rel);
    } else {
      d.retry.failed_again(policy_, before);
    }
  }
  frame.timestamp_ns = 0;
  std::uint32_t dark = 0;
  cv::Mat bgr;
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    Node& d = nodes_[k];
    cv::Mat& depth = frame.images[2 * k];
    cv::Mat& colour = frame.images[2 * k + 1];
    if (!d.open) {
      depth = cv::Mat();
      colour = cv::Mat();
      dark |= 1u << k;
      continue;
    }
    // A fresh depth image per frame (the frame's images go on to the channel's reader).
    cv::Mat got;
    std::int64_t stamp = 0;
    const V4l2Z16Device::Grab g = d.depth->grab(got, stamp, wait_ms_);
    bool read = false;
    try {
      read = g == V4l2Z16Device::Grab::frame && d.colour.read(bgr) && !bgr.empty();
    } catch (const cv::Exception&) {
      read = false;
    }
    const bool failed = g == V4l2Z16Device::Grab::failed ||
                        (g == V4l2Z16Device::Grab::frame && !read);  // the colour node stopped
    depth = cv::Mat();
    colour = cv::Mat();
    dark |= 1u << k;
    if (failed) {
      went_dark(k, crease::rt::now_ns());
      continue;
    }
    if (g != V4l2Z16Device::Grab::frame) {
      missed_depth_.fetch_add(1, std::memory_order_acq_rel);
      continue;
    }
    if (bgr.type() != CV_8UC3 || bgr.cols != got.cols || bgr.rows != got.rows) {
      wrong_colour_.fetch_add(1, std::memory_order_acq_rel);
      continue;
    }
    depth = got;
    colour = bgr.clone();
    dark &= ~(1u << k);
    if (frame.timestamp_ns == 0) frame.timestamp_ns = stamp;
  }
  if (frame.timestamp_ns == 0) frame.timestamp_ns = crease::rt::now_ns();
  dark_.store(dark, std::memory_order_release);
  return true;  // live cameras do not end
}

}  // namespace crease::vision
