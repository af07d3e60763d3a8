// crease-markers end to end: the files it writes, and its sheet.png read back by the detector.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <doctest/doctest.h>
#include <opencv2/imgcodecs.hpp>

#include "plugins/camera_rig/marker_layout.h"
#include "plugins/vision/marker_detector.h"

using namespace crease::vision;

namespace {
int run(const std::string& args) {
  return std::system((std::string(CREASE_BIN_DIR) + "/crease-markers " + args + " > /dev/null 2>&1").c_str());
}
}  // namespace

TEST_CASE("crease-markers writes pdf, png and layout; the png is read back exactly") {
  const auto dir = std::filesystem::temp_directory_path() / ("crease_markers_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  REQUIRE(run("--out " + dir.string() + " --double-sided --dpi 150") == 0);
  for (const char* f : {"sheet.pdf", "sheet.png", "sheet_back.png", "layout.yaml"})
    CHECK(std::filesystem::exists(dir / f));
  const MarkerLayout L = load_layout((dir / "layout.yaml").string());
  REQUIRE(L.markers.size() == 70);
  const double ppm = 150 / 25.4;
  for (const char* page : {"sheet.png", "sheet_back.png"}) {
    const cv::Mat img = cv::imread((dir / page).string(), cv::IMREAD_GRAYSCALE);
    REQUIRE(!img.empty());
    MarkerDetector det(DetectorConfig{.max_id = L.max_id()});
    std::vector<MarkerDetection> found;
    det.detect(img, found);
    CHECK(found.size() == 35);
    const bool back = std::string(page) == "sheet_back.png";
    for (const auto& d : found) {
      const int li = L.index_of(d.id);
      REQUIRE(li >= 0);
      const auto& m = L.markers[static_cast<std::size_t>(li)];
      CHECK(static_cast<int>(m.face) == (back ? 1 : 0));
      for (int k = 0; k < 4; ++k) {
        // Pixel centre convention: sheet mm = (px + 0.5) / ppm; the back page is mirrored in u.
        double u = (d.corners[k].x + 0.5) / ppm;
        const double v = (d.corners[k].y + 0.5) / ppm;
        if (back) u = L.sheet_w_mm - u;
        CHECK(std::hypot(u - m.corners_mm[k].x, v - m.corners_mm[k].y) < 0.1);
      }
    }
  }
  CHECK(run("--out " + dir.string() + " --grid 5by7") != 0);
  CHECK(run("--out " + dir.string() + " --marker-mm 60") != 0);
}
