// Plugin `camera_replay`: plays a recorded directory (replay_source.h, replay layout) into the
// frame channel at its recorded rate, one frame per request; in lockstep with its reader (the
// default), so every recorded frame is detected, in order, and the same recording gives the same
// key-points every time. Frames are decoded ahead (`read_ahead` frame sets) on `decode_threads`
// threads of the source's own, and stamped with the replay's time: the first frame with the time
// the plugin started playing (its first update's request, CLOCK_MONOTONIC), the others their
// recorded interval after it, so a recording made at any earlier time reaches the model as fresh (a
// late frame moves the start: replay_source.h). Parameters: replay_dir: DIR (its camK.yaml are the
// cameras), read_ahead (1..64, default 4), decode_threads (1..16, default 2), and
// camera_plugin.h's. Built twice: `camera_replay` plays a grey recording into `images` / `frames`;
// `camera_depth_replay` (CREASE_DEPTH_REPLAY) a depth recording (camera_source.h: 16-bit depth
// and colour PNGs, depth_unit_mm in the calibrations) into `depth_images` / `depth_frames`, as
// camera_depth_sim publishes them. Each refuses the other's recording (a configure error).
// Outputs: frames (crease::CameraFrames); replay_lag (Figure: how far behind its recorded time
// each frame was handed out, ms; 0 when on time) and replay_late (Figure: the share of frames
// played late, i.e. at or after the next frame was due, %: 100 per late frame, 0 per frame on
// time). Degraded when a camera's files stop, at the end, and while the newest frame was late;
// the first late frame after frames on time is logged (RT log, with the running count), and the
// totals (frames, late, worst lag, rate achieved) are printed at deactivate.
#include <cstdio>

#include "core/port_types/figure.h"
#include "plugins/cameras/camera_plugin.h"
#include "plugins/cameras/replay_source.h"

namespace {

using namespace crease::vision;

class CameraReplayPlugin final : public CameraPlugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    const int ahead = p.get_in_range<int>("read_ahead", static_cast<int>(ReplaySource::kDefaultReadAhead), 1, 64);
    const int decoders = p.get_in_range<int>("decode_threads", ReplaySource::kDefaultDecoders, 1, 16);
    auto src = std::make_unique<ReplaySource>(p.get_path("replay_dir"), static_cast<std::size_t>(ahead), decoders);
    source_ = src.get();  // owned by the worker, which lives until cleanup()
    lag_ = crease::Figure::named("camera_replay lag behind the recording", "ms", "frames played");
    late_ = crease::Figure::named("camera_replay frames played late", "%", "frames played");
    lag_out_ = ports.latest_output<crease::Figure>("replay_lag", lag_);
    late_out_ = ports.latest_output<crease::Figure>("replay_late", late_);
    seen_played_ = seen_late_ = 0;
    const bool depth = !src->depth_units_mm().empty();
#if defined(CREASE_DEPTH_REPLAY)
    if (!depth)
      p.fail("replay_dir",
             "a recording of grey cameras (no depth_unit_mm in cam0.yaml): use camera_replay");
    configure_camera(p, ports, std::move(src), true, kDepthImagesPort, kDepthFramesPort);
#else
    if (depth)
      p.fail("replay_dir",
             "a depth recording (depth_unit_mm in cam0.yaml): use camera_depth_replay");
    configure_camera(p, ports, std::move(src));
#endif
  }

  crease::Status update(const crease::Cycle& cycle) override {
    crease::Status s = CameraPlugin::update(cycle);
    const std::uint64_t played = source_->played(), late = source_->late();  // the source's atomics
    if (played != seen_played_) {
      const bool newest_late = late != seen_late_;
      const double lag_ms = static_cast<double>(source_->last_lag_ns()) * 1e-6;
      const auto n = static_cast<double>(played - seen_played_);
      // One sample per frame played since the last cycle (at most one in lockstep).
      lag_.count = played;
      lag_.sum += n * lag_ms;
      lag_.last = lag_ms;
      lag_.max = static_cast<double>(source_->max_lag_ns()) * 1e-6;
      late_.set_share(played, late, seen_late_);
      lag_out_.write(lag_, cycle.time_ns);
      late_out_.write(late_, cycle.time_ns);
      if (newest_late && !behind_)
        log_rt(crease::rt::LogLevel::warn, "replay behind its recorded rate; frames late so far",
               static_cast<std::int64_t>(late));
      behind_ = newest_late;
      seen_played_ = played;
      seen_late_ = late;
    }
    if (behind_ && s == crease::Status::ok) s = crease::Status::degraded;
    return s;
  }

  void deactivate() override {
    CameraPlugin::deactivate();
    const std::uint64_t played = source_->played();
    const double span_s = static_cast<double>(source_->last_delivery_ns() - source_->first_start_ns()) * 1e-9;
    std::fprintf(stderr,
                 "camera_replay %s: %llu of %zu frames played, %llu late, lag last %.1f ms, worst %.1f ms, "
                 "%.2f frames/s\n",
                 instance_name().c_str(), static_cast<unsigned long long>(played), source_->frames(),
                 static_cast<unsigned long long>(source_->late()), static_cast<double>(source_->last_lag_ns()) * 1e-6,
                 static_cast<double>(source_->max_lag_ns()) * 1e-6,
                 played > 1 && span_s > 0 ? static_cast<double>(played - 1) / span_s : 0.0);
  }

 private:
  const ReplaySource* source_ = nullptr;
  crease::Figure lag_{}, late_{};
  crease::LatestOutput<crease::Figure> lag_out_, late_out_;
  std::uint64_t seen_played_ = 0, seen_late_ = 0;
  bool behind_ = false;
};

}  // namespace

#if defined(CREASE_DEPTH_REPLAY)
CREASE_PLUGIN(CameraReplayPlugin, "camera_depth_replay", "1.0.0")
#else
CREASE_PLUGIN(CameraReplayPlugin, "camera_replay", "1.1.0")
#endif
