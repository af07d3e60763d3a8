// Runs the DepthTracker on a worker thread (non-RT: it takes milliseconds) over the frame sets a
// depth source publishes into its frame channel (`depth_images`), with the newest sheet model
// state the RT side handed over, and hands the targets back without locks or allocation: a
// FrameSetWorker (core/frames/frame_set_worker.h), as the vision worker does with key-points.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/frames/frame_channel.h"
#include "core/frames/frame_set_worker.h"
#include "core/port_types/depth_targets.h"
#include "core/port_types/sheet_state.h"
#include "plugins/depth_tracking/depth_tracker.h"
#include "rt/latest.h"

namespace crease::depth {

class DepthWorker {
 public:
  // `channel` holds `cameras`' images (plugins/camera_rig/depth_camera.h; CREASE_DEMAND). The
  // reader end is claimed now if free, else on the worker thread once the previous reader
  // released it (a hot swap).
  DepthWorker(std::shared_ptr<crease::frames::FrameChannel> channel,
              const std::vector<vision::DepthCamera>& cameras, const TrackerParams& params);
  ~DepthWorker();
  DepthWorker(const DepthWorker&) = delete;
  DepthWorker& operator=(const DepthWorker&) = delete;

  // RT-safe: the model's newest state for the next frames (copied into a latest channel).
  void set_model_rt(const crease::SheetState& model, std::int64_t now_ns) noexcept {
    model_.write(&model, now_ns);
  }
  using Take = crease::frames::FrameSetWorker::Take;
  // RT-safe. Copies the newest result into `out` when there is one not yet taken.
  Take take_rt(crease::DepthTargets& out) noexcept { return worker_.take_rt(&out); }
  [[nodiscard]] std::uint64_t sets_processed() const noexcept { return worker_.sets_processed(); }
  // Any thread (atomics): camera views delivered, and of those dropped for a bad pose (a carried
  // camera's pose not finite, no rotation, or missing: DepthTracker::process).
  [[nodiscard]] std::uint64_t views() const noexcept {
    return views_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::uint64_t bad_pose_views() const noexcept {
    return bad_pose_views_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::string error() const { return worker_.error(); }  // non-RT, valid after `failed`

 private:
  void process(const crease::frames::FrameSet& set);  // worker thread

  DepthTracker tracker_;
  std::unique_ptr<crease::SheetState> model_buf_;  // worker thread
  std::unique_ptr<crease::DepthTargets> result_;   // worker thread
  std::vector<cv::Mat> depth_, bgr_;               // worker thread: headers over the set
  std::vector<crease::frames::CameraPose> poses_;  // worker thread: per camera, its depth image's
  std::atomic<std::uint64_t> views_{0}, bad_pose_views_{0};
  crease::rt::LatestChannel model_{sizeof(crease::SheetState)};
  crease::frames::FrameSetWorker worker_;  // last: its thread stops before the members above go
};

}  // namespace crease::depth
