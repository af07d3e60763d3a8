// crease-bench vision_split: what splitting the camera source from detection costs in latency.
// Five 1280x960 rendered views of the half-folding sheet per frame, request -> key-points:
//  (a) ours: CameraWorker (render, copy into the frame channel, publish) -> VisionWorker
//      (woken by the publish, detects in place) -> key-points taken by an RT-style poller
//      (polling every 0.1 ms, as a loop's update would find them at its next cycle);
//  (b) the alternative, the former single-plugin path: one thread renders then detects.
// Frames alternate between the two so both meet the same load from the rest of the machine.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

#include "bench_registry.h"
#include "plugins/camera_rig/images_port.h"
#include "plugins/camera_rig/marker_sheet.h"
#include "plugins/cameras/camera_worker.h"
#include "plugins/sim_world/scene/sim_source.h"
#include "plugins/vision/keypoint_pipeline.h"
#include "plugins/vision/vision_worker.h"
#include "rt/clock.h"

using namespace crease::vision;

namespace {
double pct(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1,
                    static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
}

int run_vision_split(int argc, char** argv) {
  int frames = 30;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--frames") && i + 1 < argc) {
      frames = std::max(2, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: crease-bench vision_split [--frames N]\n");
      return 2;
    }
  }
  LayoutSpec spec;
  spec.double_sided = true;
  const MarkerLayout layout = make_layout(spec);
  const auto rig = default_rig();
  auto renderer = std::make_shared<const ViewRenderer>(
      face_texture(layout, Face::kFront, 8), face_texture(layout, Face::kBack, 8), 8, rig);
  const SheetMesh flat = flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0}, 0.1);
  auto mesh_at = [&](std::uint64_t i) {
    return fold_sheet(flat, layout.sheet_h_mm / 2, std::min(3.0, 0.1 * static_cast<double>(i)));
  };
  RenderOptions ro;
  ro.occluders = 1;
  auto channel =
      std::make_shared<crease::frames::FrameChannel>("bench.vision_split", channel_specs(rig));
  CameraWorker camera(std::make_unique<SimSource>(renderer, mesh_at, ro, 66'666'667), channel, "");
  VisionWorker vision(channel, rig, layout, DetectorConfig{}, TriangulationConfig{});
  SimSource direct_src(renderer, mesh_at, ro, 66'666'667);
  KeypointPipeline direct(rig, layout, DetectorConfig{}, TriangulationConfig{});

  std::printf("vision_split bench: %d frames x %zu cameras 1280x960, request -> key-points\n",
              frames, rig.size());
  auto kp = std::make_unique<crease::Keypoints>();
  auto kp_direct = std::make_unique<crease::Keypoints>();
  std::vector<double> ours, alt;
  std::uint32_t ours_count = 0, alt_count = 0;
  Frame f;
  for (int i = 0; i < frames; ++i) {
    // (a) request through the camera worker, wait for the key-points the way an update finds them.
    CameraWorker::Published pub;
    const std::int64_t t0 = crease::rt::now_ns();
    (void)camera.take_and_request_rt(pub, true);
    bool done = false;
    while (!done) {
      std::this_thread::sleep_for(std::chrono::microseconds(100));
      (void)camera.take_and_request_rt(pub, false);
      done = vision.take_rt(*kp) == VisionWorker::Take::fresh;
    }
    const std::int64_t t1 = crease::rt::now_ns();
    (void)camera.take_and_request_rt(pub, false);  // collect the announcement
    // (b) the former path: render then detect on one thread.
    const std::int64_t t2 = crease::rt::now_ns();
    direct_src.grab(f);
    direct.process(f.images, f.timestamp_ns, *kp_direct);
    const std::int64_t t3 = crease::rt::now_ns();
    if (i == 0) continue;  // warm-up
    ours.push_back(static_cast<double>(t1 - t0) * 1e-6);
    alt.push_back(static_cast<double>(t3 - t2) * 1e-6);
    ours_count += kp->count;
    alt_count += kp_direct->count;
  }
  const double o50 = pct(ours, 0.5), o95 = pct(ours, 0.95), a50 = pct(alt, 0.5),
               a95 = pct(alt, 0.95);
  std::printf(
      "  ours   (camera worker -> frame channel -> vision worker): p50 %.2f ms  p95 %.2f ms  "
      "key-points %u\n",
      o50, o95, ours_count);
  std::printf(
      "  direct (render then detect, one thread):                  p50 %.2f ms  p95 %.2f ms  "
      "key-points %u\n",
      a50, a95, alt_count);
  std::printf(
      "vision_split: ours_p50_ms=%.2f direct_p50_ms=%.2f ours_p95_ms=%.2f direct_p95_ms=%.2f "
      "ratio_p50=%.3f same_keypoints=%d\n",
      o50, a50, o95, a95, o50 / a50, ours_count == alt_count ? 1 : 0);
  return 0;
}
}  // namespace

CREASE_BENCH(vision_split,
             "camera source split from detection: request -> key-points latency vs one thread",
             run_vision_split);
