#include "vision_worker.h"

#include <chrono>
#include <thread>

#include <doctest/doctest.h>

#include "rt/alloc_guard.h"
#include "vision_fixture.h"

using namespace crease::vision;
using namespace std::chrono_literals;

namespace {
// Two small cameras so the test stays fast under sanitizers.
std::vector<Camera> small_rig() {
  return {look_at_camera("a", 480, 360, 500, {0, -60, 450}, {0, 0, 0}),
          look_at_camera("b", 480, 360, 500, {250, 250, 350}, {0, 0, 0})};
}

// A source that delivers `frames` frames, camera 1 missing from frame 2 on.
class FlakySource final : public CameraSource {
 public:
  FlakySource(std::shared_ptr<const ViewRenderer> r, SheetMesh mesh, int frames)
      : sim_(std::move(r), [mesh](std::uint64_t) { return mesh; }, RenderOptions{}, 1000), left_(frames) {}
  const std::vector<Camera>& cameras() const override { return sim_.cameras(); }
  bool grab(Frame& f) override {
    if (left_-- <= 0) return false;
    sim_.grab(f);
    if (f.index >= 2) f.images[1] = cv::Mat();
    return true;
  }

 private:
  SimSource sim_;
  int left_;
};
}  // namespace

TEST_CASE("worker hands frames to the RT side without allocating; end of source is reported") {
  crease::vision::testing::Scene s;
  auto r = std::make_shared<const ViewRenderer>(face_texture(s.layout, Face::kFront, 4),
                                                face_texture(s.layout, Face::kBack, 4), 4, small_rig());
  VisionWorker w(std::make_unique<FlakySource>(r, s.flat(), 4), s.layout, DetectorConfig{}, TriangulationConfig{}, "");
  CHECK(w.all_cameras_mask() == 0x3u);
  auto kp = std::make_unique<crease::Keypoints>();
  std::vector<std::uint32_t> cams_ok;
  VisionWorker::Take t = VisionWorker::Take::none;
  const auto before = crease::rt::rt_allocation_count();
  for (int i = 0; i < 3000 && t != VisionWorker::Take::ended; ++i) {
    {
      crease::rt::ScopedRtMark mark;
      t = w.take_and_request_rt(*kp);
    }
    if (t == VisionWorker::Take::fresh) cams_ok.push_back(kp->cameras_ok);
    std::this_thread::sleep_for(2ms);
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  CHECK(t == VisionWorker::Take::ended);
  REQUIRE(cams_ok.size() == 4);
  CHECK(cams_ok[0] == 0x3u);
  CHECK(cams_ok[3] == 0x1u);
  if (crease::rt::alloc_hooks_installed()) {  // the counter would have seen an allocation
    crease::rt::ScopedRtMark mark;
    static char* volatile sink;  // keeps the allocation from being elided
    sink = new char[8];
    CHECK(crease::rt::rt_allocation_count() > before);
    delete[] sink;
  }
}
