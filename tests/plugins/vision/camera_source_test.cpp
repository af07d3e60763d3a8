#include "camera_source.h"

#include <filesystem>
#include <fstream>

#include <doctest/doctest.h>

#include "keypoint_pipeline.h"
#include "vision_fixture.h"

using namespace crease::vision;

namespace {
std::string tmp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("crease_vision_src_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  return dir.string();
}

std::vector<crease::Keypoints> run(CameraSource& src, const MarkerLayout& layout, int frames) {
  KeypointPipeline pipe(src.cameras(), layout, DetectorConfig{}, TriangulationConfig{});
  std::vector<crease::Keypoints> out;
  Frame f;
  for (int i = 0; i < frames && src.grab(f); ++i) {
    out.emplace_back();
    pipe.process(f.images, f.timestamp_ns, out.back());
  }
  return out;
}
}  // namespace

TEST_CASE("a recorded sequence replayed twice gives identical key-points") {
#ifdef CREASE_SANITIZER_ADDRESS
  constexpr std::size_t kFrames = 2;  // rendering is slow under the sanitizer
#else
  constexpr std::size_t kFrames = 3;
#endif
  crease::vision::testing::Scene s;
  auto renderer = std::shared_ptr<const ViewRenderer>(std::move(s.renderer));
  const SheetMesh flat = flat_sheet(22, 31, s.layout.sheet_w_mm, s.layout.sheet_h_mm, {0, 0, 0}, 0.1);
  SimSource sim(renderer, [&](std::uint64_t i) { return fold_sheet(flat, s.layout.sheet_h_mm / 2, 0.3 * double(i)); },
                RenderOptions{.seed = 5, .occluders = 1}, 33'333'333);
  const std::string dir = tmp_dir("rec");
  {
    Recorder rec(dir, sim.cameras());
    Frame f;
    for (std::size_t i = 0; i < kFrames; ++i) {
      REQUIRE(sim.grab(f));
      rec.write(f);
    }
  }
  CHECK(std::filesystem::exists(dir + "/cam4/00000" + std::to_string(kFrames - 1) + ".png"));
  CHECK(std::filesystem::exists(dir + "/cam0.yaml"));
  ReplaySource a(dir), b(dir);
  CHECK(a.frames() == kFrames);
  const auto ka = run(a, s.layout, 10), kb = run(b, s.layout, 10);
  REQUIRE(ka.size() == kFrames);
  REQUIRE(kb.size() == kFrames);
  for (std::size_t i = 0; i < kFrames; ++i) {
    CHECK(ka[i].timestamp_ns == static_cast<std::int64_t>(i) * 33'333'333);
    REQUIRE(ka[i].count == kb[i].count);
    CHECK(ka[i].count > 100);
    CHECK(std::memcmp(ka[i].points, kb[i].points, sizeof(crease::Keypoint) * ka[i].count) == 0);
  }
}

TEST_CASE("a camera whose files stop leaves the others running; bad recordings name the file") {
  crease::vision::testing::Scene s;
  auto renderer = std::shared_ptr<const ViewRenderer>(std::move(s.renderer));
  const SheetMesh flat = flat_sheet(22, 31, s.layout.sheet_w_mm, s.layout.sheet_h_mm, {0, 0, 0}, 0.1);
  SimSource sim(renderer, [&](std::uint64_t) { return flat; }, RenderOptions{}, 10);
  const std::string dir = tmp_dir("gap");
  {
    Recorder rec(dir, sim.cameras());
    Frame f;
    for (int i = 0; i < 2; ++i) {
      REQUIRE(sim.grab(f));
      rec.write(f);
    }
  }
  std::filesystem::remove(dir + "/cam3/000001.png");
  ReplaySource r(dir);
  const auto k = run(r, s.layout, 10);
  REQUIRE(k.size() == 2);
  CHECK(k[0].cameras_ok == 0x1f);
  CHECK(k[1].cameras_ok == 0x17);
  CHECK(k[1].count == 35 * 5);

  std::ofstream(dir + "/timestamps.csv") << "frame,timestamp_ns\n0;12\n";
  CHECK_THROWS_WITH_AS(ReplaySource{dir}, doctest::Contains("timestamps.csv: line 2"), std::runtime_error);
  CHECK_THROWS_WITH_AS(ReplaySource{tmp_dir("nothing")}, doctest::Contains("cam0.yaml"), std::runtime_error);
}
