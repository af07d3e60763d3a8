// Shared synthetic scene for the vision tests: the default double-sided layout, its textures,
// the seed-000 rig and a renderer.
#pragma once

#include <chrono>
#include <filesystem>
#include <iterator>
#include <memory>
#include <thread>

#include <opencv2/core/utility.hpp>

#include "camera_model.h"
#include "marker_layout.h"
#include "marker_sheet.h"
#include "sheet_mesh.h"
#include "view_renderer.h"

namespace crease::vision::testing {

struct Scene {
  MarkerLayout layout;
  std::unique_ptr<ViewRenderer> renderer;
  static constexpr double kTexPpm = 8.0;

  Scene() {
    LayoutSpec spec;
    spec.double_sided = true;
    layout = make_layout(spec);
    renderer = std::make_unique<ViewRenderer>(face_texture(layout, Face::kFront, kTexPpm),
                                              face_texture(layout, Face::kBack, kTexPpm), kTexPpm,
                                              default_rig());
  }
  [[nodiscard]] SheetMesh flat() const {
    return flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0}, 0.1);
  }
};

// For the tests of our threads (label `concurrency`, run under ThreadSanitizer): OpenCV runs
// its parallel loops inline on the calling thread, so it starts no TBB workers and every thread
// in the process is one of ours. TBB's workers run uninstrumented code that synchronises
// through futexes TSan cannot see; buffers they touch (memcpy, free) would show as races in our
// code. With this, TSan sees every access and every hand-over. Process-wide; call it first.
// Under TSan it also starts the runtime's background thread now (it starts with the first
// thread created), so that process_threads() counts from here on are exact.
inline void own_threads_only() {
  cv::setNumThreads(1);
#ifdef CREASE_SANITIZER_THREAD
  std::thread([] {}).join();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the kernel reaps it
#endif
}

// Threads of this process now (/proc/self/task) but the sanitizer runtime's own (TSan runs one
// background thread, started by own_threads_only()): checks that no thread but ours exists.
inline long process_threads() {
#ifdef CREASE_SANITIZER_THREAD
  constexpr long kRuntimeThreads = 1;
#else
  constexpr long kRuntimeThreads = 0;
#endif
  const std::filesystem::directory_iterator it("/proc/self/task");
  return std::distance(begin(it), end(it)) - kRuntimeThreads;
}

// True image position of a layout point on the mesh (pixels), false if behind the camera.
inline bool true_pixel(const Camera& cam, const SheetMesh& mesh, const cv::Point2d& uv, cv::Point2d& px) {
  return cam.project(mesh.world_at(uv.x, uv.y), px);
}

}  // namespace crease::vision::testing
