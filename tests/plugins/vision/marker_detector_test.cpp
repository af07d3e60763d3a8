#include "plugins/vision/marker_detector.h"

#include <doctest/doctest.h>
#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>

#include "plugins/sim_world/scene/view_renderer.h"

using namespace crease::vision;

TEST_CASE("no false marker id over 100 clutter frames (tags of other ids are present)") {
  constexpr int kLayoutMaxId = 69;
  DetectorConfig cfg;
  cfg.max_id = kLayoutMaxId;
  DetectorConfig all = cfg;
  all.max_id = -1;
  int false_ids = 0, foreign = 0;
  for (std::uint64_t seed = 0; seed < 100; ++seed) {
    const cv::Mat img = render_clutter(1280, 960, seed, kLayoutMaxId);
    MarkerDetector det(cfg), det_all(all);
    std::vector<MarkerDetection> out;
    det.detect(img, out);
    false_ids += static_cast<int>(out.size());
    det_all.detect(img, out);
    for (const auto& d : out) foreign += d.id > kLayoutMaxId;
  }
  MESSAGE("foreign tags seen " << foreign);
  CHECK(false_ids == 0);
  CHECK(foreign > 50);  // the clutter does hold real tags; only the layout filter keeps them out
}

TEST_CASE("edge refinement puts corners of a rendered tag within 0.1 px") {
  // A tag drawn by area coverage at a known sub-pixel position, lightly blurred.
  const auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  cv::Mat tag;
  cv::aruco::drawMarker(dict, 5, 400, tag, 1);
  cv::Mat big(800, 800, CV_8U, cv::Scalar(255));
  tag.copyTo(big(cv::Rect(200, 200, 400, 400)));
  // Downscale by 8 with area averaging: tag corners at (200/8 - 0.5) = 24.5 .. 74.5 px.
  cv::Mat img;
  cv::resize(big, img, cv::Size(100, 100), 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(img, img, cv::Size(), 0.6);
  const cv::Point2f truth[4] = {{24.5f, 24.5f}, {74.5f, 24.5f}, {74.5f, 74.5f}, {24.5f, 74.5f}};
  std::array<cv::Point2f, 4> c = {truth[0] + cv::Point2f(0.8f, -0.6f), truth[1] + cv::Point2f(-0.5f, 0.7f),
                                   truth[2] + cv::Point2f(0.9f, 0.4f), truth[3] + cv::Point2f(-0.7f, -0.8f)};
  REQUIRE(refine_corners_edges(img, c));
  for (int k = 0; k < 4; ++k) CHECK(cv::norm(c[k] - truth[k]) < 0.1);
  int id = -1;
  REQUIRE(decode_tag(img, *dict, 0.3, c, id));
  CHECK(id == 5);
  for (int k = 0; k < 4; ++k) CHECK(cv::norm(c[k] - truth[k]) < 0.1);  // already in tag order
}
