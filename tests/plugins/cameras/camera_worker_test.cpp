// CameraWorker: one requested frame -> one published set in the frame channel (valid flags per
// camera, pixels, recording), end of source, no allocation on the RT side, and the hand-over of
// the writer end from an old worker to a new one (a hot swap). Label `concurrency` too: under
// ThreadSanitizer with OpenCV kept on our threads (own_threads_only), so that TSan checks the
// RT side against the worker and the hand-over between workers.
#include "plugins/cameras/camera_worker.h"
#include "plugins/cameras/replay_source.h"

#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "plugins/camera_rig/images_port.h"
#include "plugins/sim_world/scene/marker_scene.h"
#include "plugins/sim_world/scene/sim_source.h"
#include "rt/alloc_guard.h"
#include "support/abort_message.h"
#include "support/opencv_threads.h"

using namespace crease::vision;
using namespace std::chrono_literals;

namespace {
std::vector<Camera> small_rig() {
  return {look_at_camera("a", 320, 240, 330, {0, -60, 450}, {0, 0, 0}),
          look_at_camera("b", 320, 240, 330, {250, 250, 350}, {0, 0, 0})};
}

// Delivers `frames` frames, camera 1 missing from frame 2 on.
class FlakySource final : public CameraSource {
 public:
  FlakySource(std::shared_ptr<const ViewRenderer> r, SheetMesh mesh, int frames)
      : sim_(
            std::move(r), [mesh](std::uint64_t) { return mesh; }, RenderOptions{}, 1000),
        left_(frames) {}
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

std::shared_ptr<const ViewRenderer> renderer(const crease::vision::testing::Scene& s) {
  return std::make_shared<const ViewRenderer>(face_texture(s.layout, Face::kFront, 2),
                                              face_texture(s.layout, Face::kBack, 2), 2,
                                              small_rig());
}

// Polls like an RT update would until something other than `none` comes.
CameraWorker::Take poll(CameraWorker& w, CameraWorker::Published& p, bool request = true) {
  CameraWorker::Take t = CameraWorker::Take::none;
  for (int i = 0; i < 5000 && t == CameraWorker::Take::none; ++i) {
    {
      crease::rt::ScopedRtMark mark;
      t = w.take_and_request_rt(p, request);
    }
    if (t == CameraWorker::Take::none) std::this_thread::sleep_for(1ms);
  }
  return t;
}
}  // namespace

TEST_CASE("each requested frame is published once, with per-camera flags; the end is reported") {
  crease::testing::own_threads_only();
  crease::vision::testing::Scene s;
  const auto dir = std::filesystem::temp_directory_path() /
                   ("crease_camera_worker_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  auto ch = std::make_shared<crease::frames::FrameChannel>("camera_worker_test",
                                                           channel_specs(small_rig()));
  REQUIRE(ch->try_claim_reader());
  std::vector<std::uint32_t> masks;
  {
    CameraWorker w(std::make_unique<FlakySource>(renderer(s), s.flat(), 3), ch, dir.string());
    CHECK(ch->writer_claimed());
    CHECK(crease::testing::process_threads() == 2);  // this one and the worker
    const auto before = crease::rt::rt_allocation_count();
    CameraWorker::Published p;
    CameraWorker::Take t = CameraWorker::Take::none;
    while ((t = poll(w, p)) == CameraWorker::Take::fresh) {
      masks.push_back(p.valid_mask);
      const auto* set = ch->acquire_newest();
      REQUIRE(set != nullptr);
      CHECK(set->sequence == p.sequence);
      CHECK(set->frame == p.frame);
      CHECK(set->valid_mask == p.valid_mask);
      CHECK(set->stamp_ns == static_cast<std::int64_t>(p.frame) * 1000);
      int bright = 0;  // the white page fills part of the view
      for (std::size_t i = 0; i < ch->image_bytes(0); ++i) bright += set->pixels(0)[i] > 128;
      CHECK(bright > 1000);
    }
    CHECK(t == CameraWorker::Take::ended);
    CHECK(crease::rt::rt_allocation_count() == before);
  }
  CHECK_FALSE(ch->writer_claimed());  // released with the worker
  CHECK(masks == std::vector<std::uint32_t>{0x3u, 0x3u, 0x1u});
  CHECK(std::filesystem::exists(dir / "cam1" / "000001.png"));
  CHECK_FALSE(std::filesystem::exists(dir / "cam1" / "000002.png"));  // camera b delivered nothing
  CHECK(std::filesystem::exists(dir / "cam0" / "000002.png"));
  ReplaySource replay(dir.string());
  CHECK(replay.frames() == 3);
  if (crease::rt::alloc_hooks_installed()) {  // the counter would have seen an allocation
    const auto before = crease::rt::rt_allocation_count();
    crease::rt::ScopedRtMark mark;
    static char* volatile sink;
    sink = new char[8];
    CHECK(crease::rt::rt_allocation_count() > before);
    delete[] sink;
  }
}

TEST_CASE("a new worker waits for the old one's writer end (hot swap), then publishes") {
  crease::testing::own_threads_only();
  crease::vision::testing::Scene s;
  auto ch = std::make_shared<crease::frames::FrameChannel>("camera_worker_test.swap",
                                                           channel_specs(small_rig()));
  auto old_worker = std::make_unique<CameraWorker>(
      std::make_unique<FlakySource>(renderer(s), s.flat(), 5), ch, "");
  CameraWorker::Published p;
  REQUIRE(poll(*old_worker, p) == CameraWorker::Take::fresh);  // and asks for the next one
  CHECK(p.sequence == 1);
  REQUIRE(poll(*old_worker, p, false) == CameraWorker::Take::fresh);  // asks for no more
  CHECK(p.sequence == 2);

  CameraWorker fresh(std::make_unique<FlakySource>(renderer(s), s.flat(), 5), ch, "");
  {
    crease::rt::ScopedRtMark mark;
    CHECK(fresh.take_and_request_rt(p, true) == CameraWorker::Take::none);
  }
  std::this_thread::sleep_for(50ms);
  {
    crease::rt::ScopedRtMark mark;
    CHECK(fresh.take_and_request_rt(p, true) ==
          CameraWorker::Take::none);  // still waiting for the writer end
  }
  CHECK(ch->published() == 2);
  CHECK(crease::testing::process_threads() == 3);  // this one and the two workers: ours
  old_worker.reset();  // the old instance goes: its worker releases the writer end
  REQUIRE(poll(fresh, p) == CameraWorker::Take::fresh);
  CHECK(p.sequence == 3);  // the channel's sequence goes on
  CHECK(p.frame == 0);     // the new source's first frame
}

TEST_CASE("a channel with other cameras than the source's is a bug: the worker aborts") {
  // Plugins get the channel from the port registry, which checked the cameras
  // (plugins/camera_rig/images_port.h).
  crease::vision::testing::Scene s;
  auto ch = std::make_shared<crease::frames::FrameChannel>(
      "camera_worker_test.other", std::vector<crease::frames::CameraSpec>{{"a", 320, 240}});
  auto source = std::make_unique<FlakySource>(renderer(s), s.flat(), 1);  // here: the child only aborts
  const std::string why =
      crease::testing::abort_message([&] { CameraWorker w(std::move(source), ch, ""); });
  CHECK(why.find("internal error at") != std::string::npos);
  CHECK(why.find("the frame channel does not have this source's cameras") != std::string::npos);
  CHECK_FALSE(ch->writer_claimed());
}
