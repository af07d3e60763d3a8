// Plugin `depth_tracking` (vision loop): the depth path of seed 001 (issue 17). The frame sets of
// a depth source (`depth_images`, kind frames: plugins/camera_rig/depth_camera.h) go through the
// DepthTracker on a worker thread (depth_worker.h) with the sheet model's newest state as CPD's
// warm start; the targets come out on `depth_targets` for the sheet model's point-to-plane
// springs. The update only hands the model state over and copies the newest result out.
//   in:  depth_images (frames), sheet_state (latest, SheetState)
//   out: depth_targets (latest, DepthTargets)
// Parameters: cameras: DIR (the depth calibrations, with depth_unit_mm; a camera the robot
// carries, camera_mount.h, is a configuration error: its pose changes every frame) and
// depth_tracker.h's.
// Status: degraded when the newest result has no target (no model state yet, no cloud: an
// empty mask, no valid depth, a camera dark) or a camera delivered nothing; fault when the
// worker failed.
#include <cstdio>
#include <memory>

#include "core/plugin.h"
#include "core/port_types/depth_targets.h"
#include "core/port_types/sheet_state.h"
#include "plugins/camera_rig/depth_camera.h"
#include "plugins/depth_tracking/depth_worker.h"

namespace {

using namespace crease;

class DepthTrackingPlugin final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    const auto cams = vision::load_depth_camera_dir(p.get_path("cameras", "depth_cameras"));
    for (const auto& c : cams)  // its points are put in the world with each camera's fixed pose
      if (c.mount)
        p.fail("cameras", c.camera.name + " is carried (" + vision::describe(*c.mount) +
                              "): the depth path takes cameras fixed in the world only");
    const depth::TrackerParams tp = depth::tracker_params_from(p);
    all_cameras_ = cams.size() >= 32 ? 0xffffffffu : (1u << cams.size()) - 1u;
    auto channel = vision::bind_depth_images(ports, vision::cameras_of(cams), vision::ImagesEnd::reader);
    model_ = ports.latest_input<SheetState>("sheet_state");
    out_ = ports.latest_output<DepthTargets>("depth_targets", DepthTargets{});
    result_ = std::make_unique<DepthTargets>();
    worker_ = std::make_unique<depth::DepthWorker>(std::move(channel), cams, tp);
  }

  Status update(const Cycle& cycle) override {
    if (model_.poll().is_new()) worker_->set_model_rt(model_.value(), cycle.time_ns);
    switch (worker_->take_rt(*result_)) {
      case depth::DepthWorker::Take::fresh:
        out_.write(*result_, cycle.time_ns);
        have_ = true;
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
  }
  void cleanup() override { worker_.reset(); }

 private:
  LatestInput<SheetState> model_;
  LatestOutput<DepthTargets> out_;
  std::unique_ptr<DepthTargets> result_;
  std::unique_ptr<depth::DepthWorker> worker_;
  std::uint32_t all_cameras_ = 0;
  bool have_ = false;
};

}  // namespace

CREASE_PLUGIN(DepthTrackingPlugin, "depth_tracking", "0.1.0")
