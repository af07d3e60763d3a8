// VisionWorker: woken by each set published into a frame channel, key-points handed to the RT
// side without allocation; calibrations that do not match the channel are refused. Label
// `concurrency` too: under ThreadSanitizer with OpenCV kept on our threads (own_threads_only),
// TSan checks the channel hand-over (this thread writes, the worker reads) and the result
// hand-off to the RT side.
#include "plugins/vision/vision_worker.h"

#include <doctest/doctest.h>

#include <chrono>
#include <cstring>
#include <thread>

#include "plugins/camera_rig/images_port.h"
#include "plugins/cameras/camera_worker.h"
#include "plugins/sim_world/scene/marker_scene.h"
#include "rt/alloc_guard.h"
#include "support/abort_message.h"
#include "support/opencv_threads.h"

using namespace crease::vision;
using namespace std::chrono_literals;

namespace {
// Two small cameras so the test stays fast under sanitizers.
std::vector<Camera> small_rig() {
  return {look_at_camera("a", 480, 360, 500, {0, -60, 450}, {0, 0, 0}),
          look_at_camera("b", 480, 360, 500, {250, 250, 350}, {0, 0, 0})};
}
}  // namespace

TEST_CASE("each published set is detected once, without allocating on the RT side") {
  crease::testing::own_threads_only();
  crease::vision::testing::Scene s;
  const ViewRenderer r(face_texture(s.layout, Face::kFront, 4),
                       face_texture(s.layout, Face::kBack, 4), 4, small_rig());
  std::vector<RenderedView> views(2);
  for (int k = 0; k < 2; ++k)
    r.render(k, s.flat(), RenderOptions{}, views[static_cast<std::size_t>(k)]);

  auto ch = std::make_shared<crease::frames::FrameChannel>("vision_worker_test",
                                                           channel_specs(small_rig()));
  REQUIRE(ch->try_claim_writer());
  VisionWorker w(ch, small_rig(), s.layout, DetectorConfig{}, TriangulationConfig{});
  CHECK(w.all_cameras_mask() == 0x3u);
  CHECK(ch->reader_claimed());

  auto kp = std::make_unique<crease::Keypoints>();
  std::vector<std::uint32_t> cams_ok;
  std::vector<std::int64_t> stamps;
  std::uint32_t first_count = 0;
  const auto before = crease::rt::rt_allocation_count();
  for (std::uint64_t f = 0; f < 4; ++f) {
    for (std::size_t k = 0; k < 2; ++k)
      std::memcpy(ch->write_slot().pixels(k), views[k].image.data, ch->image_bytes(k));
    ch->publish(1000 + static_cast<std::int64_t>(f), f,
                f >= 2 ? 0x1u : 0x3u);  // camera b stops at frame 2
    VisionWorker::Take t = VisionWorker::Take::none;
    for (int i = 0; i < 5000 && t == VisionWorker::Take::none; ++i) {
      {
        crease::rt::ScopedRtMark mark;
        t = w.take_rt(*kp);
      }
      if (t == VisionWorker::Take::none) std::this_thread::sleep_for(1ms);
    }
    REQUIRE(t == VisionWorker::Take::fresh);
    cams_ok.push_back(kp->cameras_ok);
    stamps.push_back(kp->timestamp_ns);
    if (f == 0) first_count = kp->count;
    crease::rt::ScopedRtMark mark;
    CHECK(w.take_rt(*kp) == VisionWorker::Take::none);  // taken once
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  CHECK(cams_ok == std::vector<std::uint32_t>{0x3u, 0x3u, 0x1u, 0x1u});
  CHECK(stamps == std::vector<std::int64_t>{1000, 1001, 1002, 1003});
  CHECK(first_count > 20);  // key-points seen by both cameras
  CHECK(ch->consumed() == 4);
  CHECK(w.sets_processed() == 4);
  CHECK(crease::testing::process_threads() == 2);  // this one and the worker: no TBB
  if (crease::rt::alloc_hooks_installed()) {  // the counter would have seen an allocation
    crease::rt::ScopedRtMark mark;
    static char* volatile sink;  // keeps the allocation from being elided
    sink = new char[8];
    CHECK(crease::rt::rt_allocation_count() > before);
    delete[] sink;
  }
}

TEST_CASE("calibrations that do not match the channel are a bug; a worker releases its reader end") {
  // Plugins get the channel from the port registry, which checked the cameras
  // (plugins/camera_rig/images_port.h).
  crease::vision::testing::Scene s;
  auto ch = std::make_shared<crease::frames::FrameChannel>("vision_worker_test.b",
                                                           channel_specs(small_rig()));
  auto other = small_rig();
  other[1].width = 640;
  const std::string why = crease::testing::abort_message(
      [&] { VisionWorker w(ch, other, s.layout, DetectorConfig{}, TriangulationConfig{}); });
  CHECK(why.find("the frame channel does not have these cameras") != std::string::npos);
  { VisionWorker w(ch, small_rig(), s.layout, DetectorConfig{}, TriangulationConfig{}); }
  CHECK_FALSE(ch->reader_claimed());
}

TEST_CASE("cameras detected on helper threads of ours give the same key-points as one by one") {
  crease::testing::own_threads_only();
  crease::vision::testing::Scene s;
  const ViewRenderer r(face_texture(s.layout, Face::kFront, 4),
                       face_texture(s.layout, Face::kBack, 4), 4, small_rig());
  auto ch = std::make_shared<crease::frames::FrameChannel>("vision_worker_test.team",
                                                           channel_specs(small_rig()));
  REQUIRE(ch->try_claim_writer());
  std::vector<RenderedView> views(2);
  for (int k = 0; k < 2; ++k)
    r.render(k, s.flat(), RenderOptions{}, views[static_cast<std::size_t>(k)]);
  std::vector<std::unique_ptr<crease::Keypoints>> kps;
  for (const int threads : {1, 2}) {
    CAPTURE(threads);
    for (std::size_t k = 0; k < 2; ++k)  // the same images for each worker
      std::memcpy(ch->write_slot().pixels(k), views[k].image.data, ch->image_bytes(k));
    ch->publish(7, 0, 0x3u);
    VisionWorker w(ch, small_rig(), s.layout, DetectorConfig{}, TriangulationConfig{}, threads);
    kps.push_back(std::make_unique<crease::Keypoints>());
    VisionWorker::Take t = VisionWorker::Take::none;
    for (int i = 0; i < 5000 && t == VisionWorker::Take::none; ++i) {
      t = w.take_rt(*kps.back());
      if (t == VisionWorker::Take::none) std::this_thread::sleep_for(1ms);
    }
    REQUIRE(t == VisionWorker::Take::fresh);
    // This thread, the worker and its threads - 1 helpers: all ours.
    CHECK(crease::testing::process_threads() == 1 + threads);
  }
  REQUIRE(kps[0]->count > 20);
  REQUIRE(kps[0]->count == kps[1]->count);
  CHECK(std::memcmp(kps[0]->points, kps[1]->points, sizeof(crease::Keypoint) * kps[0]->count) == 0);
  // The plugin reads camera_threads in [0, 64]: a negative count is a bug.
  CHECK(crease::testing::abort_message([&] {
          VisionWorker w(ch, small_rig(), s.layout, DetectorConfig{}, TriangulationConfig{}, -1);
        }).find("camera_threads: expected 0") != std::string::npos);
}
