#include "plugins/camera_rig/marker_sheet.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

#include <doctest/doctest.h>

#include "plugins/camera_rig/marker_layout.h"

using namespace crease::vision;

namespace {
std::string tmp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("crease_marker_sheet_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}
}  // namespace

TEST_CASE("page raster: black cells where the layout says, white paper elsewhere") {
  LayoutSpec spec;
  const MarkerLayout L = make_layout(spec);
  const double ppm = 4.0;
  const cv::Mat page = render_page(L, Face::kFront, ppm);
  CHECK(page.cols == 840);
  CHECK(page.rows == 1188);
  const auto& m = L.markers[0];
  // Inside the black border ring (half a cell from the outer edge) is black; outside is white.
  const double cell = L.marker_mm / 8;
  auto at = [&](double u, double v) { return page.at<uchar>(int(v * ppm), int(u * ppm)); };
  CHECK(at(m.corners_mm[0].x + cell / 2, m.corners_mm[0].y + cell / 2) == 0);
  CHECK(at(m.corners_mm[0].x - cell / 2, m.corners_mm[0].y - cell / 2) == 255);
  CHECK(at(105, 1) == 255);
}

TEST_CASE("PDF: well-formed header, one page per face, xref at the stated offset") {
  LayoutSpec spec;
  spec.double_sided = true;
  const std::string p = tmp_path("sheet.pdf");
  write_sheet_pdf(make_layout(spec), p);
  std::ifstream f(p, std::ios::binary);
  const std::string s((std::istreambuf_iterator<char>(f)), {});
  CHECK(s.rfind("%PDF-1.4", 0) == 0);
  CHECK(s.find("/Count 2") != std::string::npos);
  CHECK(s.find("/MediaBox [0 0 595.2756 841.8898]") != std::string::npos);
  const auto sx = s.rfind("startxref\n");
  REQUIRE(sx != std::string::npos);
  const long off = std::stol(s.substr(sx + 10));
  CHECK(s.compare(static_cast<std::size_t>(off), 4, "xref") == 0);
}
