#include "plugins/camera_rig/marker_layout.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <doctest/doctest.h>

#include "core/errors.h"

using namespace crease::vision;

namespace {
std::string tmp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("crease_vision_layout_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}
}  // namespace

TEST_CASE("default layout: 35 markers per face, distinct ids on the back, inside the page") {
  LayoutSpec spec;
  spec.double_sided = true;
  const MarkerLayout L = make_layout(spec);
  REQUIRE(L.markers.size() == 70);
  CHECK(L.sheet_w_mm == 210.0);
  CHECK(L.sheet_h_mm == 297.0);
  for (const auto& m : L.markers) {
    CHECK(L.index_of(m.id) >= 0);
    for (const auto& c : m.corners_mm) {
      CHECK(c.x > 0);
      CHECK(c.x < 210);
      CHECK(c.y > 0);
      CHECK(c.y < 297);
    }
    // Front corners run clockwise in (u, v) (v down); back corners run the other way.
    const double cross = (m.corners_mm[1] - m.corners_mm[0]).cross(m.corners_mm[2] - m.corners_mm[1]);
    CHECK((m.face == Face::kFront ? cross > 0 : cross < 0));
    CHECK(cv::norm(m.corners_mm[1] - m.corners_mm[0]) == doctest::Approx(spec.marker_mm));
  }
  CHECK(L.markers[0].face == Face::kFront);
  CHECK(L.markers[35].face == Face::kBack);
  // The back of the top-left front tag's page position is the top-right of the back page.
  CHECK(L.markers[35].centre_mm.x == doctest::Approx(210 - L.markers[0].centre_mm.x));
}

TEST_CASE("layout round-trips through layout.yaml") {
  LayoutSpec spec;
  spec.double_sided = true;
  spec.cols = 4;
  spec.rows = 5;
  spec.marker_mm = 30;
  const MarkerLayout L = make_layout(spec);
  const std::string p = tmp_path("layout.yaml");
  save_layout(L, p);
  const MarkerLayout R = load_layout(p);
  REQUIRE(R.markers.size() == L.markers.size());
  CHECK(R.dictionary == L.dictionary);
  CHECK(R.marker_mm == L.marker_mm);
  for (std::size_t i = 0; i < L.markers.size(); ++i) {
    CHECK(R.markers[i].id == L.markers[i].id);
    CHECK(R.markers[i].face == L.markers[i].face);
    for (int k = 0; k < 4; ++k) CHECK(cv::norm(R.markers[i].corners_mm[k] - L.markers[i].corners_mm[k]) < 1e-9);
  }
}

TEST_CASE("bad layouts are refused with the file and key") {
  const std::string p = tmp_path("bad.yaml");
  {
    std::ofstream(p) << "dictionary: apriltag36h11\nsheet_size_mm: [210, 297]\nmarker_mm: 28\nmarkers:\n"
                        "  - {id: 1, face: front, centre: [10, 10]}\n";
  }
  // FILE:LINE:COLUMN: KEY: reason, the place of the map the key is missing from.
  CHECK_THROWS_WITH_AS(load_layout(p), (p + ":5:5: markers[0].corners: missing").c_str(), crease::ConfigError);
  { std::ofstream(p) << "dictionary: nosuch\nsheet_size_mm: [210, 297]\nmarker_mm: 28\nmarkers: []\n"; }
  CHECK_THROWS_WITH_AS(load_layout(p), doctest::Contains((p + ":1:13: dictionary: unknown dictionary 'nosuch'").c_str()),
                       crease::ConfigError);
  { std::ofstream(p) << "dictionary: apriltag36h11\nsheet_size_mm: [210, 297]\nmarker_mm: 28\nmarkers:\n"
                        "  - {id: 1, face: top, centre: [10, 10], corners: [[0, 0], [1, 0], [1, 1], [0, 1]]}\n"; }
  CHECK_THROWS_WITH_AS(load_layout(p), (p + ":5:19: markers[0].face: expected front or back").c_str(),
                       crease::ConfigError);
  CHECK_THROWS_WITH_AS(load_layout(tmp_path("missing.yaml")), doctest::Contains("missing.yaml"), crease::ConfigError);
  LayoutSpec big;
  big.marker_mm = 45;  // does not fit 5 columns on A4 with a quiet zone
  CHECK_THROWS_WITH_AS(make_layout(big), doctest::Contains("do not fit a 5x7 grid"), crease::ConfigError);
}
