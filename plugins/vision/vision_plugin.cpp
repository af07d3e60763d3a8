// Plugin `vision`: marker detection and N-view triangulation of the frame sets a camera source
// plugin (plugins/cameras: camera_sim, camera_replay, camera_v4l2) publishes -> `keypoints` port.
// The images come through the frame channel of the `images` port
// (plugins/camera_rig/images_port.h, kind `frames`), not through a latest port: five 1280x960
// images are 6 MB a set. The `frames` port (crease::CameraFrames) carries the source's
// announcement. Detection and triangulation run on a worker thread woken by each publish
// (VisionWorker); update() only copies the newest key-points out: no allocation, no lock, no
// wait.
//
// Parameters (paths relative to the configuration file's folder):
//   cameras: DIR of cam0.yaml.. (the calibrations of the channel's cameras, in order; for a
//            replay, the recording's folder)
//   layout: layout.yaml     decimate, full_search_interval; max_reproj_px, refine; stale_cycles
//   camera_threads: 0 (default: cameras detected in parallel by OpenCV's pool) or N >= 1 (one
//            task per camera on the worker and N-1 helper threads of ours, task_team.h; OpenCV's
//            loops inside each detection still use its pool unless cv::setNumThreads(1))
// Inputs: images (frames), frames (crease::CameraFrames). Outputs: keypoints (crease::Keypoints),
// and two figures (crease::Figure, shown in creased's progress, `creasectl stats` and the report):
// detect_time (ms of detection and triangulation per frame set, on the worker) and
// keypoints_per_set (key-points triangulated per frame set).
// Status: degraded when a camera delivered nothing, no new key-points came for
// `stale_cycles` cycles, or the source ended; fault if the worker failed.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "core/plugin.h"
#include "core/port_types/camera_frames.h"
#include "core/port_types/figure.h"
#include "core/port_types/keypoints.h"
#include "plugins/camera_rig/images_port.h"
#include "plugins/vision/vision_worker.h"

namespace {

using namespace crease::vision;

class VisionPlugin final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    const MarkerLayout layout = load_layout(p.get_path("layout", "markers/layout.yaml"));
    auto cams = load_camera_dir(p.get_path("cameras", "cameras"));
    DetectorConfig det;
    det.decimate = p.get_in_range<int>("decimate", 2, 1, 4);
    det.full_search_interval = p.get_in_range<int>("full_search_interval", 8, 1, 1000);
    TriangulationConfig tri;
    tri.max_reproj_px = p.get_in_range<double>("max_reproj_px", 2.0, 0.1, 50.0);
    tri.refine = p.get<bool>("refine", true);
    stale_cycles_ = p.get_in_range<int>("stale_cycles", 10, 1, 100000);
    const int camera_threads = p.get_in_range<int>("camera_threads", 0, 0, 64);
    // Binds the channel with these calibrations' cameras: a source with other cameras fails
    // to configure (this end or the source, whichever binds second) with a message naming the
    // channel and the camera.
    auto channel = bind_images(ports, cams, ImagesEnd::reader);
    std::memcpy(channel_name_, channel->name().c_str(), channel->name().size() + 1);
    buf_ = std::make_unique<crease::Keypoints>();
    frames_in_ = ports.latest_input<crease::CameraFrames>("frames");
    out_ = ports.latest_output<crease::Keypoints>("keypoints", crease::Keypoints{});
    detect_ = crease::Figure::named("vision detection per frame set", "ms", "frame sets");
    per_set_ = crease::Figure::named("vision key-points per frame set", "kp", "frame sets");
    detect_out_ = ports.latest_output<crease::Figure>("detect_time", detect_);
    per_set_out_ = ports.latest_output<crease::Figure>("keypoints_per_set", per_set_);
    worker_ = std::make_unique<VisionWorker>(std::move(channel), std::move(cams), layout, det, tri,
                                             camera_threads);
  }

  crease::Status update(const crease::Cycle& cycle) override {
    bool source_degraded = false;
    if (frames_in_.poll().has_data()) {
      const crease::CameraFrames& announce = frames_in_.value();
      if (std::strncmp(announce.channel, channel_name_, sizeof channel_name_) != 0) {
        if (!warned_channel_)
          log_rt(crease::rt::LogLevel::warn, "the frames port announces another frame channel");
        warned_channel_ = true;
        source_degraded = true;
      }
      source_degraded = source_degraded || announce.ended != 0;
    }
    switch (worker_->take_rt(*buf_)) {
      case VisionWorker::Take::fresh:
        out_.write(*buf_, cycle.time_ns);
        since_fresh_ = 0;
        write_figures(cycle.time_ns);
        return buf_->cameras_ok == worker_->all_cameras_mask() && !source_degraded
                   ? crease::Status::ok
                   : crease::Status::degraded;
      case VisionWorker::Take::none:
        return ++since_fresh_ > stale_cycles_ || source_degraded ? crease::Status::degraded
                                                                 : crease::Status::ok;
      case VisionWorker::Take::failed:
        log_rt(crease::rt::LogLevel::error, "vision worker failed (see host log)");
        return crease::Status::fault;
    }
    return crease::Status::fault;
  }

  // RT: the worker's times so far, and the key-points of the set just taken.
  void write_figures(std::int64_t now_ns) noexcept {
    const VisionWorker::ProcessTimes t = worker_->process_times();
    detect_.count = t.count;
    detect_.sum = static_cast<double>(t.sum_ns) * 1e-6;
    detect_.last = static_cast<double>(t.last_ns) * 1e-6;
    detect_.max = static_cast<double>(t.max_ns) * 1e-6;
    const auto n = static_cast<double>(buf_->count);
    per_set_.count += 1;
    per_set_.sum += n;
    per_set_.last = n;
    per_set_.max = std::max(per_set_.max, n);
    detect_out_.write(detect_, now_ns);
    per_set_out_.write(per_set_, now_ns);
  }

  // Non-RT, after a fault too: says why the worker stopped, if it did.
  void deactivate() override {
    if (worker_ && !worker_->error().empty())
      std::fprintf(stderr, "%s: vision worker failed: %s\n", instance_name().c_str(),
                   worker_->error().c_str());
  }
  void cleanup() override { worker_.reset(); }

 private:
  std::unique_ptr<VisionWorker> worker_;
  std::unique_ptr<crease::Keypoints> buf_;
  crease::LatestInput<crease::CameraFrames> frames_in_;
  crease::LatestOutput<crease::Keypoints> out_;
  crease::Figure detect_{}, per_set_{};  // per_set_ counts the sets taken, detect_ the sets processed
  crease::LatestOutput<crease::Figure> detect_out_, per_set_out_;
  char channel_name_[crease::CameraFrames::kChannelNameCapacity] = {};
  bool warned_channel_ = false;
  int stale_cycles_ = 10;
  int since_fresh_ = 0;
};

}  // namespace

CREASE_PLUGIN(VisionPlugin, "vision", "1.0.0")
