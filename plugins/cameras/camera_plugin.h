// The common part of the camera source plugins (camera_sim, camera_replay, camera_v4l2):
// a CameraSource on a CameraWorker publishing into the frame channel of the `images` port
// (plugins/camera_rig/images_port.h), and the `frames` port (crease::CameraFrames) announcing
// each published set.
// Compiled into each camera plugin library (header-only: plugins share no code at run time
// except through core).
//
// Common parameters (paths relative to the configuration file's folder, Params::get_path):
//   record: DIR          write every grabbed frame in the replay layout (an RGB-D source's:
//                        16-bit depth and colour PNGs, camera_source.h)
//   lockstep: bool       grab the next frame only once the reader finished the last one
//                        (default true: capture and detection take turns, as one thread did
//                        before the split, so the newest frame is grabbed when detection can
//                        take it, and a replay is processed frame by frame; false: grab every
//                        cycle, the reader takes the newest set)
//   stale_cycles: N      degraded after N cycles without a new frame (default 10)
// Status: degraded when a camera delivered nothing in the last set, no set came for
// `stale_cycles`, or the source ended; fault when the worker failed.
#pragma once

#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "core/plugin.h"
#include "core/port_types/camera_frames.h"
#include "plugins/camera_rig/depth_camera.h"
#include "plugins/camera_rig/images_port.h"
#include "plugins/cameras/camera_source.h"
#include "plugins/cameras/camera_worker.h"

namespace crease::vision {

// The live cameras' parameters (camera_v4l2, camera_depth_v4l2; non-RT, configure time).
// KEY: a list of device paths, each resolved against the configuration's folder.
inline std::vector<std::string> read_device_list(const crease::Params& p, const char* key) {
  std::vector<std::string> out;
  const YAML::Node d = p.raw(key);
  if (!d || !d.IsSequence()) p.fail(key, "expected a list of video devices");
  for (const auto& n : d) out.push_back(p.resolve_path(n.as<std::string>()));
  return out;
}
// reconnect_initial_s (default 0.5) and reconnect_max_s (default 5), the latter at least the
// former.
inline ReconnectPolicy read_reconnect_policy(const crease::Params& p) {
  ReconnectPolicy retry;
  retry.initial_s = p.get_in_range<double>("reconnect_initial_s", 0.5, 0.001, 60.0);
  retry.max_s = p.get_in_range<double>("reconnect_max_s", 5.0, 0.001, 3600.0);
  if (retry.max_s < retry.initial_s)
    p.fail("reconnect_max_s", "must be at least reconnect_initial_s");
  return retry;
}

class CameraPlugin : public crease::Plugin {
 public:
  crease::Status update(const crease::Cycle& cycle) override {
    const bool request =
        !lockstep_ || !channel_->reader_claimed() || channel_->finished() >= channel_->published();
    CameraWorker::Published pub;
    switch (worker_->take_and_request_rt(pub, request)) {
      case CameraWorker::Take::fresh:
        announce_.sequence = pub.sequence;
        announce_.frame = pub.frame;
        announce_.stamp_ns = pub.stamp_ns;
        announce_.valid_mask = pub.valid_mask;
        out_.write(announce_, cycle.time_ns);
        since_fresh_ = 0;
        return pub.valid_mask == channel_->all_cameras_mask() ? crease::Status::ok
                                                              : crease::Status::degraded;
      case CameraWorker::Take::none:
        if (++since_fresh_ > stale_cycles_) return crease::Status::degraded;
        return announce_.valid_mask == channel_->all_cameras_mask() || announce_.sequence == 0
                   ? crease::Status::ok
                   : crease::Status::degraded;
      case CameraWorker::Take::ended:
        if (announce_.ended == 0) {
          announce_.ended = 1;
          out_.write(announce_, cycle.time_ns);
        }
        return crease::Status::degraded;
      case CameraWorker::Take::failed:
        log_rt(crease::rt::LogLevel::error, "camera worker failed (see host log)");
        return crease::Status::fault;
    }
    return crease::Status::fault;
  }

  // RT: logs (with the running count) when a live source's reconnect count N moved since the
  // last call.
  void log_reconnects_rt(std::uint64_t n, const char* what) noexcept {
    if (n == reported_reconnects_) return;
    reported_reconnects_ = n;
    log_rt(crease::rt::LogLevel::info, what, static_cast<std::int64_t>(n));
  }

  // Non-RT, after a fault too: says why the worker stopped, if it did.
  void deactivate() override {
    if (worker_ && !worker_->error().empty())
      std::fprintf(stderr, "%s: camera worker failed: %s\n", instance_name().c_str(),
                   worker_->error().c_str());
  }
  void cleanup() override { worker_.reset(); }

 protected:
  // Call last in configure, with the source the parameters describe. The images go through the
  // frame channel of port `images_port`, announced on `frames_port` (an RGB-D source: its own).
  void configure_camera(const crease::Params& p, crease::PortBinder& ports,
                        std::unique_ptr<CameraSource> source, bool lockstep_default = true,
                        const char* images_port = kImagesPort, const char* frames_port = "frames") {
    lockstep_ = p.get<bool>("lockstep", lockstep_default);
    reported_reconnects_ = 0;
    stale_cycles_ = p.get_in_range<int>("stale_cycles", 10, 1, 100000);
    const std::string record = p.has("record") ? p.get_path("record") : std::string();
    // The replay layouts: one grey image per camera, or an RGB-D camera's depth and colour.
    const bool grey = source->channel_images() == channel_specs(source->cameras());
    const bool depth = source->channel_images() == depth_channel_specs(source->cameras()) &&
                       source->depth_units_mm().size() == source->cameras().size();
    if (!record.empty() && !grey && !depth)
      p.fail("record", "this source's images have no replay layout");
    channel_ = bind_image_specs(ports, images_port, source->channel_images(), ImagesEnd::writer);
    std::memcpy(announce_.channel, channel_->name().c_str(), channel_->name().size() + 1);
    announce_.cameras = static_cast<std::uint32_t>(source->cameras().size());
    out_ = ports.latest_output<crease::CameraFrames>(frames_port, crease::CameraFrames{});
    worker_ = std::make_unique<CameraWorker>(std::move(source), channel_, record);
  }

 private:
  std::shared_ptr<crease::frames::FrameChannel> channel_;
  std::unique_ptr<CameraWorker> worker_;
  crease::LatestOutput<crease::CameraFrames> out_;
  crease::CameraFrames announce_{};
  bool lockstep_ = false;
  int stale_cycles_ = 10;
  int since_fresh_ = 0;
  std::uint64_t reported_reconnects_ = 0;
};

}  // namespace crease::vision
