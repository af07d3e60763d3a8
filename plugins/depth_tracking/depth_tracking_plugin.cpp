// Plugin `depth_tracking` (vision loop): the depth path of seed 001 (issue 17). The frame sets of
// a depth source (`depth_images`, kind frames: plugins/camera_rig/depth_camera.h) go through the
// DepthTracker on a worker thread (depth_worker.h) with the sheet model's newest state as CPD's
// warm start; the targets come out on `depth_targets` for the sheet model's point-to-plane
// springs. The update only hands the model state over and copies the newest result out.
//   in:  depth_images (frames), sheet_state (latest, SheetState)
//   out: depth_targets (latest, DepthTargets); bad_pose (latest, Figure: the share of camera
//        views dropped for their pose, %, per camera view)
// Parameters: cameras: DIR (the depth calibrations, with depth_unit_mm; a camera the robot
// carries, camera_mount.h, is put in the world with the pose its every frame carries, the frame
// channel's CameraPose) and depth_tracker.h's.
// Status: degraded when the newest result has no target (no model state yet, no cloud: an
// empty mask, no valid depth, a camera dark) or a camera delivered nothing (or its view was
// dropped for a bad pose); fault when the worker failed.
#include <cstdio>
#include <memory>
#include <string>

#include "core/plugin.h"
#include "core/port_types/depth_targets.h"
#include "core/port_types/figure.h"
#include "core/port_types/sheet_state.h"
#include "plugins/camera_rig/depth_camera.h"
#include "plugins/depth_tracking/depth_worker.h"

namespace {

using namespace crease;

class DepthTrackingPlugin final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    const auto cams = vision::load_depth_camera_dir(p.get_path("cameras", "depth_cameras"));
    if (cams.size() > 16)  // two images each in a frame set of at most 32
      p.fail("cameras", std::to_string(cams.size()) + " depth cameras, at most 16");
    const depth::TrackerParams tp = depth::tracker_params_from(p);
    all_cameras_ = cams.size() >= 32 ? 0xffffffffu : (1u << cams.size()) - 1u;
    auto channel = vision::bind_depth_images(ports, vision::cameras_of(cams), vision::ImagesEnd::reader);
    model_ = ports.latest_input<SheetState>("sheet_state");
    out_ = ports.latest_output<DepthTargets>("depth_targets", DepthTargets{});
    bad_pose_ =
        Figure::named("depth_tracking camera views dropped for a bad pose", "%", "camera views");
    bad_pose_out_ = ports.latest_output<Figure>("bad_pose", bad_pose_);
    seen_views_ = seen_bad_ = 0;
    result_ = std::make_unique<DepthTargets>();
    worker_ = std::make_unique<depth::DepthWorker>(std::move(channel), cams, tp);
  }

  Status update(const Cycle& cycle) override {
    if (model_.poll().is_new()) worker_->set_model_rt(model_.value(), cycle.time_ns);
    switch (worker_->take_rt(*result_)) {
      case depth::DepthWorker::Take::fresh:
        out_.write(*result_, cycle.time_ns);
        have_ = true;
        report_bad_pose_rt(cycle.time_ns);
        break;
      case depth::DepthWorker::Take::failed:
        log_rt(rt::LogLevel::error, "depth worker failed (see host log)");
        return Status::fault;
      case depth::DepthWorker::Take::none:
        break;
    }
    if (!have_) return Status::ok;  // nothing processed yet
    return result_->count > 0 && result_->cameras_ok == all_cameras_ ? Status::ok : Status::degraded;
  }

  void deactivate() override {
    if (worker_ && !worker_->error().empty())
      std::fprintf(stderr, "%s: depth worker failed: %s\n", instance_name().c_str(), worker_->error().c_str());
    if (worker_ && worker_->bad_pose_views() > 0)
      std::fprintf(stderr, "%s: %llu of %llu camera views dropped for a bad pose\n",
                   instance_name().c_str(),
                   static_cast<unsigned long long>(worker_->bad_pose_views()),
                   static_cast<unsigned long long>(worker_->views()));
  }
  void cleanup() override { worker_.reset(); }

 private:
  // RT: the views dropped for their pose into the `bad_pose` figure when the views moved.
  void report_bad_pose_rt(std::int64_t now_ns) noexcept {
    const std::uint64_t bad = worker_->bad_pose_views(), views = worker_->views();
    if (views == seen_views_) return;
    bad_pose_.set_share(views, bad, seen_bad_);
    bad_pose_out_.write(bad_pose_, now_ns);
    seen_views_ = views;
    seen_bad_ = bad;
  }

  LatestInput<SheetState> model_;
  Figure bad_pose_{};
  LatestOutput<Figure> bad_pose_out_;
  std::uint64_t seen_views_ = 0, seen_bad_ = 0;
  LatestOutput<DepthTargets> out_;
  std::unique_ptr<DepthTargets> result_;
  std::unique_ptr<depth::DepthWorker> worker_;
  std::uint32_t all_cameras_ = 0;
  bool have_ = false;
};

}  // namespace

CREASE_PLUGIN(DepthTrackingPlugin, "depth_tracking", "0.1.0")
