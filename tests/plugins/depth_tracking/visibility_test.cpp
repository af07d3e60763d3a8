// NodeVisibility (plugins/depth_tracking/visibility.h) with the shipped overhead D435: a flat
// sheet is seen whole; folded over (175 deg) the lower layer under the flap is hidden from
// above and the flap is seen; a surface the depth camera measures in front of a node hides it.
#include "plugins/depth_tracking/visibility.h"

#include <doctest/doctest.h>

#include "plugins/camera_rig/depth_camera.h"
#include "plugins/sim_world/scene/fold_script.h"

using crease::depth::NodeVisibility;

namespace {
const std::string kSrc = CREASE_SOURCE_DIR;

std::vector<Eigen::Vector3d> nodes_at(const crease::sheet::FoldScript& s, double t) {
  std::vector<crease::sheet::Vec3> x(15 * 21);
  s.node_positions(t, x);
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : x) out.emplace_back(p.x, p.y, p.z);
  return out;
}
}  // namespace

TEST_CASE("flat: every node seen from above; folded: the lower layer under the flap hidden") {
  const auto cams = crease::vision::cameras_of(crease::vision::load_depth_camera_dir(kSrc + "/config/depth_cameras"));
  crease::sheet::GridParams g;
  g.origin_mm = {-105.0, 148.5, 0.5};
  const auto script = crease::sheet::FoldScript::half_fold(g);
  NodeVisibility vis;
  vis.configure({cams[0]}, 15, 21, 4, 1);
  std::vector<std::uint32_t> seen(15 * 21);
  REQUIRE(vis.compute(nodes_at(script, 0.0), 1u, seen));
  int flat_seen = 0;
  for (auto s : seen) flat_seen += s != 0;
  CHECK(flat_seen == 15 * 21);

  REQUIRE(vis.compute(nodes_at(script, 6.0), 1u, seen));  // held at 175 deg
  // Rows j < 10 are the flap (v < h/2), rows j > 10 the lower layer under it.
  int flap = 0, flap_seen = 0, lower = 0, lower_seen = 0;
  for (int j = 0; j < 21; ++j)
    for (int i = 0; i < 15; ++i) {
      const bool s = seen[static_cast<std::size_t>(j * 15 + i)] != 0;
      if (j < 9) {
        ++flap;
        flap_seen += s;
      } else if (j > 11) {
        ++lower;
        lower_seen += s;
      }
    }
  MESSAGE("folded: flap seen " << flap_seen << "/" << flap << ", lower layer seen " << lower_seen << "/" << lower);
  CHECK(flap_seen >= flap - 2);
  CHECK(lower_seen <= lower / 10);
}

TEST_CASE(
    "depth check: a measured surface in front of a node hides it; no depth or a far one does not") {
  const auto cams = crease::vision::cameras_of(
      crease::vision::load_depth_camera_dir(kSrc + "/config/depth_cameras"));
  crease::sheet::GridParams g;
  g.origin_mm = {-105.0, 148.5, 0.5};
  const auto flat = nodes_at(crease::sheet::FoldScript::half_fold(g), 0.0);
  NodeVisibility vis;
  vis.configure({cams[0]}, 15, 21, 4, 1);
  vis.set_depth_check({1.0}, 10.0);
  std::vector<std::uint32_t> seen(15 * 21);
  const auto count = [&] {
    int n = 0;
    for (auto s : seen) n += s != 0;
    return n;
  };
  // The overhead camera sees the flat sheet ~650 mm away (along its axis). An occluder at 600 mm
  // over the left half of the image (the u < 105 mm half of the sheet), no depth on the right.
  cv::Mat depth(cams[0].height, cams[0].width, CV_16UC1, cv::Scalar(0));
  depth.colRange(0, cams[0].width / 2).setTo(cv::Scalar(600));
  std::vector<cv::Mat> images{depth};
  REQUIRE(vis.compute(flat, 1u, seen, images));
  const int half = count();
  MESSAGE("occluder over the left half: " << half << " of 315 nodes seen, "
                                          << vis.occluded_by_depth() << " hidden by depth");
  CHECK(half >= 7 * 21);  // the right half and the middle column (an occluder's edge hides nothing)
  CHECK(half <= 8 * 21);
  CHECK(vis.occluded_by_depth() == 315 - half);
  // The table seen behind the sheet (farther) hides nothing; without images nothing either.
  depth.setTo(cv::Scalar(700));
  REQUIRE(vis.compute(flat, 1u, seen, images));
  CHECK(count() == 315);
  REQUIRE(vis.compute(flat, 1u, seen));
  CHECK(count() == 315);
  // occluder_mm 0: no depth check.
  depth.setTo(cv::Scalar(600));
  vis.set_depth_check({1.0}, 0.0);
  REQUIRE(vis.compute(flat, 1u, seen, images));
  CHECK(count() == 315);
}
