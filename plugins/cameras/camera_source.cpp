#include "plugins/cameras/camera_source.h"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/assert.h"
#include "core/errors.h"
#include "plugins/camera_rig/depth_camera.h"
#include "rt/clock.h"

namespace crease::vision {

std::string replay_frame_path(const std::string& dir, std::size_t cam, std::uint64_t index) {
  char name[64];
  std::snprintf(name, sizeof name, "/cam%zu/%06" PRIu64 ".png", cam, index);
  return dir + name;
}

std::string replay_poses_path(const std::string& dir, std::size_t cam) {
  return dir + "/cam" + std::to_string(cam) + "/poses.csv";
}

std::string replay_colour_path(const std::string& dir, std::size_t cam, std::uint64_t index) {
  char name[64];
  std::snprintf(name, sizeof name, "/cam%zu/%06" PRIu64 ".colour.png", cam, index);
  return dir + name;
}

namespace {
std::int64_t seconds_to_ns(double s) { return static_cast<std::int64_t>(s * 1e9); }
}  // namespace

void ReconnectClock::went_dark(const ReconnectPolicy& p, std::int64_t now_ns) noexcept {
  backoff_s = p.initial_s;
  retry_at_ns = now_ns + seconds_to_ns(backoff_s);
}

void ReconnectClock::failed_again(const ReconnectPolicy& p, std::int64_t now_ns) noexcept {
  retry_at_ns = now_ns + seconds_to_ns(backoff_s);
  backoff_s = std::min(2.0 * backoff_s, p.max_s);
}

bool open_capture(cv::VideoCapture& cap, const std::string& path, int width, int height) {
  const bool node = path.rfind("/dev/", 0) == 0;
  const bool sequence = path.find('%') != std::string::npos;
  try {
    cap.open(path, node ? cv::CAP_V4L2 : sequence ? cv::CAP_IMAGES : cv::CAP_ANY);
    if (cap.isOpened() && node) {
      cap.set(cv::CAP_PROP_FRAME_WIDTH, width);
      cap.set(cv::CAP_PROP_FRAME_HEIGHT, height);
    }
  } catch (const cv::Exception&) {
    cap.release();  // unopenable now: retried later
  }
  return cap.isOpened();
}

V4l2Source::V4l2Source(std::vector<Camera> cameras, const std::vector<std::string>& devices,
                       ReconnectPolicy policy)
    : cameras_(std::move(cameras)), policy_(policy) {
  crease::require_input(devices.size() == cameras_.size(),
                        "camera_v4l2: " + std::to_string(devices.size()) + " devices for " +
                            std::to_string(cameras_.size()) + " calibrations");
  crease::require_input(devices.size() <= kMaxCameras, "camera_v4l2: " + std::to_string(devices.size()) +
                                                           " devices, at most " + std::to_string(kMaxCameras));
  crease::require_input(policy_.initial_s > 0.0 && policy_.max_s >= policy_.initial_s,
                        "camera_v4l2: reconnect times must satisfy 0 < initial (" +
                            std::to_string(policy_.initial_s) + " s) <= max (" + std::to_string(policy_.max_s) +
                            " s)");
  reconnects_ = std::make_unique<std::atomic<std::uint64_t>[]>(devices.size());
  devices_.resize(devices.size());
  const std::int64_t now = crease::rt::now_ns();
  std::uint32_t dark = 0;
  for (std::size_t k = 0; k < devices.size(); ++k) {
    devices_[k].path = devices[k];
    if (try_open(k)) continue;
    failed_.push_back(devices[k]);
    dark |= 1u << k;
    went_dark(k, now);
  }
  dark_.store(dark, std::memory_order_release);
}

bool V4l2Source::try_open(std::size_t k) {
  Device& d = devices_[k];
  d.open = open_capture(d.cap, d.path, cameras_[k].width, cameras_[k].height);
  return d.open;
}

void V4l2Source::went_dark(std::size_t k, std::int64_t now_ns) {
  Device& d = devices_[k];
  d.cap.release();
  d.open = false;
  d.retry.went_dark(policy_, now_ns);
}

bool V4l2Source::grab(Frame& frame) {
  frame.index = next_++;
  frame.images.resize(devices_.size());
  const std::int64_t before = crease::rt::now_ns();
  for (std::size_t k = 0; k < devices_.size(); ++k) {
    Device& d = devices_[k];
    if (d.open || !d.retry.due(before)) continue;
    if (try_open(k)) {
      reconnects_[k].fetch_add(1, std::memory_order_acq_rel);
      total_reconnects_.fetch_add(1, std::memory_order_acq_rel);
    } else {
      d.retry.failed_again(policy_, before);
    }
  }
  // grab() all first so the exposures are as close in time as the devices allow.
  std::vector<bool> ok(devices_.size());
  for (std::size_t k = 0; k < devices_.size(); ++k) {
    try {
      ok[k] = devices_[k].open && devices_[k].cap.grab();
    } catch (const cv::Exception&) {
      ok[k] = false;
    }
  }
  frame.timestamp_ns = crease::rt::now_ns();
  cv::Mat bgr;
  std::uint32_t dark = 0;
  for (std::size_t k = 0; k < devices_.size(); ++k) {
    Device& d = devices_[k];
    frame.images[k] = cv::Mat();
    bool read = ok[k];
    try {
      read = read && d.cap.retrieve(bgr) && !bgr.empty();
    } catch (const cv::Exception&) {
      read = false;
    }
    if (!read) {
      if (d.open) went_dark(k, frame.timestamp_ns);  // stopped or disconnected: reopen later
      dark |= 1u << k;
      continue;
    }
    if (bgr.channels() == 3) cv::cvtColor(bgr, frame.images[k], cv::COLOR_BGR2GRAY);
    else if (bgr.channels() == 1) frame.images[k] = bgr.clone();
    const Camera& c = cameras_[k];
    if (frame.images[k].cols != c.width || frame.images[k].rows != c.height) {
      frame.images[k] = cv::Mat();  // delivers, but not this calibration's image
      dark |= 1u << k;
    }
  }
  dark_.store(dark, std::memory_order_release);
  return true;  // live cameras do not end; a dark one delivers empty images until it is back
}

Recorder::Recorder(const std::string& dir, const std::vector<Camera>& cameras,
                   const std::vector<double>& depth_units_mm,
                   const std::vector<std::optional<CameraMount>>& mounts)
    : dir_(dir), ncam_(cameras.size()), depth_(!depth_units_mm.empty()) {
  if (depth_ && depth_units_mm.size() != cameras.size())
    throw crease::Error(dir + ": " + std::to_string(depth_units_mm.size()) + " depth units for " +
                        std::to_string(cameras.size()) + " cameras");
  if (!mounts.empty() && (!depth_ || mounts.size() != cameras.size()))
    throw crease::Error(dir +
                        ": carried cameras are recorded by an RGB-D source, one mount per camera");
  std::filesystem::create_directories(dir);
  poses_.assign(cameras.size(), nullptr);
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    std::filesystem::create_directories(dir + "/cam" + std::to_string(k));
    const std::string yaml = dir + "/cam" + std::to_string(k) + ".yaml";
    const std::optional<CameraMount> mount = k < mounts.size() ? mounts[k] : std::nullopt;
    if (depth_)
      save_depth_camera(DepthCamera{cameras[k], depth_units_mm[k], mount}, yaml);
    else
      save_camera(cameras[k], yaml);
    if (!mount) continue;
    const std::string csv = replay_poses_path(dir, k);
    poses_[k] = std::fopen(csv.c_str(), "w");
    if (poses_[k] == nullptr) throw crease::Error(csv + ": cannot open for writing");
    std::fprintf(poses_[k], "%s\n", kReplayPosesHeader);
  }
  const std::string csv = dir + "/timestamps.csv";
  stamps_ = std::fopen(csv.c_str(), "w");
  if (stamps_ == nullptr) throw crease::Error(csv + ": cannot open for writing");
  std::fprintf(stamps_, "frame,timestamp_ns\n");
}

Recorder::~Recorder() {
  if (stamps_ != nullptr) std::fclose(stamps_);
  for (std::FILE* f : poses_)
    if (f != nullptr) std::fclose(f);
}

void Recorder::write(const Frame& frame) {
  // Grey: image k is camera k's; depth: images 2k (depth) and 2k + 1 (colour) are camera k's.
  const std::size_t per = depth_ ? 2 : 1;
  for (std::size_t k = 0; k < ncam_; ++k) {
    bool delivered = false;
    for (std::size_t i = 0; i < per && per * k + i < frame.images.size(); ++i) {
      const cv::Mat& m = frame.images[per * k + i];
      if (m.empty()) continue;
      delivered = true;
      const std::string p = i == 0 ? replay_frame_path(dir_, k, frame.index)
                                   : replay_colour_path(dir_, k, frame.index);
      if (!cv::imwrite(p, m)) throw crease::Error(p + ": write failed");
    }
    // A carried camera's pose of this capture, when it delivered (a camera not posed yet has
    // neither images nor pose).
    if (poses_[k] == nullptr || !delivered || per * k >= frame.poses.size()) continue;
    const crease::frames::CameraPose& pose = frame.poses[per * k];
    if (!pose.carried) continue;
    std::fprintf(poses_[k], "%" PRIu64, frame.index);
    for (const double r : pose.rotation) std::fprintf(poses_[k], ",%.17g", r);
    for (const double x : pose.translation_mm) std::fprintf(poses_[k], ",%.17g", x);
    std::fprintf(poses_[k], "\n");
    std::fflush(poses_[k]);
  }
  std::fprintf(stamps_, "%" PRIu64 ",%" PRId64 "\n", frame.index, frame.timestamp_ns);
  std::fflush(stamps_);
}

}  // namespace crease::vision
