// The depth path with a camera the robot carries (the D405-like right wrist camera of
// config/wrist_cameras, rendered by the simulated world's DepthSimSource from where the forearm
// puts it): each frame carries the camera's pose at its capture (Frame::poses, the frame channel's
// CameraPose), the cloud goes into the world with it (point_cloud.h) and DepthTracker registers the
// model onto it. A bad pose drops the view and is counted; nothing allocates.
#include "plugins/depth_tracking/depth_tracker.h"

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "plugins/camera_rig/camera_mount.h"
#include "plugins/sim_world/scene/depth_sim_source.h"
#include "rt/alloc_guard.h"
#include "tests/plugins/sim_world/scene/forearm_rig.h"

using namespace crease::vision;
using crease::frames::CameraPose;

namespace {
const std::string kSrc = CREASE_SOURCE_DIR;
constexpr double kSheetZ = 0.5;  // the flat sheet's surface, world mm (half its 1 mm thickness)

// The plain blue sheet of camera_depth_sim (DepthColourModel: h ~ 101) through a D405's range.
crease::depth::CloudParams sheet_cloud() {
  crease::depth::CloudParams p;
  p.mask = {95, 115, 120, 255, 40, 255};
  p.min_depth_mm = 70;
  p.max_depth_mm = 500;
  p.voxel_mm = 6;
  return p;
}

// Two frames of the right wrist camera over the flat sheet: from 300 mm looking straight down,
// then after the arm moved (220 mm up, 30 mm right, 40 mm nearer the robot, tilted 20 deg).
struct TwoPoses {
  DepthCamera cam;
  Frame a, b;
  cv::Matx33d R_a, R_b;
  cv::Vec3d c_a{0, 0, 300}, c_b{30, -40, 220};
};

std::unique_ptr<TwoPoses> render_two_poses() {
  auto t = std::make_unique<TwoPoses>();
  t->cam = load_depth_camera_dir(kSrc + "/config/wrist_cameras")[0];
  REQUIRE(t->cam.mount.has_value());
  t->R_a = forearm_rig::looking_down(0);
  t->R_b = forearm_rig::looking_down(20);
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  const cv::Mat tex = DepthSimSource::plain_texture(400, 400, 1.0);
  std::vector<SceneShape> shapes = forearm_rig::forearm_carrying(t->cam.camera, t->R_a, t->c_a);
  DepthSimSource src(
      {t->cam}, tex, tex, 1.0, [&](std::uint64_t) { return flat; }, RenderOptions{},
      forearm_rig::d405(), DepthColourModel{}, 33'000'000);
  src.set_shapes_source([&](std::vector<SceneShape>& out) { out = shapes; });
  REQUIRE(src.grab(t->a));
  shapes = forearm_rig::forearm_carrying(t->cam.camera, t->R_b, t->c_b);
  REQUIRE(src.grab(t->b));
  return t;
}

struct Fit {
  int points = 0;
  double rms = 0, mean = 0, expected = 0;  // mm: from z = kSheetZ; the noise model's figure
};

// The cloud against the sheet's plane; expected: the D405 model's sigma at each point's camera z
// (the pose it was put in the world with) and the 0.1 mm quantisation.
Fit plane_fit(std::span<const Eigen::Vector3d> pts, const DepthCamera& cam, const cv::Matx33d& R,
              const cv::Vec3d& t) {
  Fit f;
  double sum = 0, sum2 = 0, var = 0;
  const crease::vision::DepthSensorModel sm = forearm_rig::d405();
  for (const Eigen::Vector3d& p : pts) {
    const double e = p[2] - kSheetZ;
    sum += e;
    sum2 += e * e;
    const double z = (R * cv::Vec3d(p[0], p[1], p[2]) + t)[2];
    const double s = depth_sigma_mm(sm, cam.camera.mean_focal_px(), z);
    var += s * s;
    ++f.points;
  }
  if (f.points == 0) return f;
  f.mean = sum / f.points;
  f.rms = std::sqrt(sum2 / f.points);
  f.expected = std::sqrt(var / f.points + cam.depth_unit_mm * cam.depth_unit_mm / 12);
  return f;
}

// The model: the flat sheet itself (the truth), as the sheet model would hold it.
std::unique_ptr<crease::SheetState> flat_model() {
  auto m = std::make_unique<crease::SheetState>();
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  m->nodes_u = 15;
  m->nodes_v = 21;
  for (std::size_t i = 0; i < flat.nodes.size(); ++i)
    for (int c = 0; c < 3; ++c) m->position_mm[i][c] = static_cast<float>(flat.nodes[i][c]);
  return m;
}

crease::depth::TrackerParams tracker_params() {
  crease::depth::TrackerParams p;
  p.cloud = sheet_cloud();
  p.cpd.max_iterations = 15;
  p.cpd.sigma2_init_mm2 = 25;
  p.cpd.sigma2_min_mm2 = 2;
  return p;
}

}  // namespace

TEST_CASE(
    "a wrist camera's cloud lands on the sheet from two arm poses, each with its frame's pose") {
  const auto t = render_two_poses();
  // Each frame carries the pose it was rendered from (both images of the camera).
  REQUIRE(t->a.poses.size() == 2);
  REQUIRE(t->b.poses.size() == 2);
  CHECK(t->a.poses[0].carried);
  CHECK(t->a.poses[1].carried);
  cv::Matx33d R_a, R_b;
  cv::Vec3d t_a, t_b;
  REQUIRE(camera_from_pose(t->a.poses[0], R_a, t_a));
  REQUIRE(camera_from_pose(t->b.poses[0], R_b, t_b));
  CHECK(cv::norm(R_a - t->R_a) < 1e-9);
  CHECK(cv::norm(R_b - t->R_b) < 1e-9);
  CHECK(cv::norm(cv::Vec3d(t->a.poses[0].translation_mm[0], t->a.poses[0].translation_mm[1],
                           t->a.poses[0].translation_mm[2]) -
                 t->c_a) < 1e-9);

  crease::depth::CloudParams cp = sheet_cloud();
  cp.camera_depth_unit_mm = {t->cam.depth_unit_mm};
  crease::depth::CloudBuilder cloud;
  cloud.configure(cp, {t->cam.camera}, 848 * 480);
  const auto fit = [&](const Frame& f, const cv::Matx33d& R, const cv::Vec3d& tt) {
    cloud.clear();
    REQUIRE(cloud.add_view(0, f.images[0], f.images[1], R, tt));
    return plane_fit(cloud.points(), t->cam, R, tt);
  };
  const Fit a = fit(t->a, R_a, t_a);
  const Fit b = fit(t->b, R_b, t_b);
  const Fit stale = fit(t->b, R_a, t_a);  // frame b put in the world with frame a's pose
  MESSAGE("cloud from pose a: " << a.points << " points, plane rms " << a.rms << " mm (model "
                                << a.expected << "), mean " << a.mean << "; pose b: " << b.points
                                << ", rms " << b.rms << " (model " << b.expected << "), mean "
                                << b.mean << "; frame b with pose a: rms " << stale.rms
                                << " mm, mean " << stale.mean);
  for (const Fit* f : {&a, &b}) {
    REQUIRE(f->points > 20000);
    // The noise is along the ray (the plane's normal within 20 deg of the axis) and a mean over a
    // finite sample: the rms within -20 % / +10 % of the model's, the mean near zero.
    CHECK(f->rms <= 1.1 * f->expected);
    CHECK(f->rms >= 0.8 * f->expected);
    CHECK(std::abs(f->mean) < 0.1);
  }
  CHECK(stale.rms > 20 * b.expected);  // the pose before the move puts the sheet far off
}

TEST_CASE(
    "DepthTracker with a wrist camera: targets on the sheet from its frame's pose; no allocation") {
  const auto t = render_two_poses();
  crease::depth::DepthTracker tracker;
  tracker.configure(tracker_params(), {t->cam});
  const auto model = flat_model();
  auto out = std::make_unique<crease::DepthTargets>();
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  // Each target against the truth at its sheet point: along z (the plane) and in all.
  const auto score = [&](double& z_worst, double& dist_mean) {
    z_worst = 0;
    dist_mean = 0;
    for (std::uint32_t i = 0; i < out->count; ++i) {
      const auto& p = out->points[i];
      const cv::Vec3d w = flat.world_at(p.sheet_mm[0], p.sheet_mm[1]);
      z_worst = std::max(z_worst, std::abs(p.world_mm[2] - w[2]));
      dist_mean += cv::norm(cv::Vec3d(p.world_mm[0], p.world_mm[1], p.world_mm[2]) - w);
    }
    if (out->count > 0) dist_mean /= out->count;
  };
  REQUIRE(crease::rt::alloc_hooks_installed());
  for (const Frame* f : {&t->a, &t->b}) {
    const std::span<const cv::Mat> depth(&f->images[0], 1), bgr(&f->images[1], 1);
    const CameraPose pose = f->poses[0];
    tracker.process(depth, bgr, *model, 1, 0, *out, {&pose, 1});  // warm-up: the same as below
    const auto before = crease::rt::rt_allocation_count();
    bool ok = false;
    {
      crease::rt::ScopedRtMark mark;
      ok = tracker.process(depth, bgr, *model, 1, 0, *out, {&pose, 1});
    }
    CHECK(crease::rt::rt_allocation_count() == before);
    REQUIRE(ok);
    double z_worst = 0, dist = 0;
    score(z_worst, dist);
    MESSAGE((f == &t->a ? "pose a" : "pose b")
            << ": " << out->count << " targets, " << out->visible_nodes << " nodes visible, "
            << out->cloud_points << " cloud points; targets off the plane at most " << z_worst
            << " mm, from their sheet point " << dist << " mm on average");
    CHECK(out->cameras_ok == 1u);
    CHECK(out->count >= 50);
    CHECK(z_worst < 2.0);  // the cloud's mean over 6 mm voxels: well under the D405's 1 mm
    CHECK(dist < 5.0);     // CPD's tangential error on a plain sheet (README: ~4 mm)
  }
  CHECK(tracker.bad_pose_views() == 0);
  // Frame b with frame a's pose: the cloud is off the sheet (what a fixed calibration would do).
  const std::span<const cv::Mat> depth(&t->b.images[0], 1), bgr(&t->b.images[1], 1);
  const CameraPose stale = t->a.poses[0];
  (void)tracker.process(depth, bgr, *model, 1, 0, *out, {&stale, 1});
  double off = 0;
  for (const Eigen::Vector3d& p : tracker.cloud().points()) off += std::abs(p[2] - kSheetZ);
  off /= std::max<std::size_t>(1, tracker.cloud().points().size());
  MESSAGE("frame b with pose a: cloud " << off << " mm off the sheet's plane on average");
  CHECK(off > 20.0);
}

TEST_CASE("DepthTracker: a carried camera's bad pose drops its view, counted, and never crashes") {
  const auto t = render_two_poses();
  crease::depth::DepthTracker tracker;
  tracker.configure(tracker_params(), {t->cam});
  const auto model = flat_model();
  auto out = std::make_unique<crease::DepthTargets>();
  const std::span<const cv::Mat> depth(&t->a.images[0], 1), bgr(&t->a.images[1], 1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<CameraPose> bad(6, t->a.poses[0]);
  bad[0].rotation[4] = nan;
  bad[1].translation_mm[2] = inf;
  bad[2].translation_mm[0] = -inf;
  for (double& r : bad[3].rotation) r *= 2;  // no rotation: a scale
  bad[4].rotation[0] = -bad[4].rotation[0];  // a reflection
  bad[5].carried = false;  // a carried camera's frame with no pose: its calibration is the mount's
  REQUIRE(crease::rt::alloc_hooks_installed());
  (void)tracker.process(depth, bgr, *model, 1, 0, *out, {&t->a.poses[0], 1});  // warm-up
  REQUIRE(out->count > 0);
  const std::uint64_t views = tracker.views();
  for (std::size_t k = 0; k < bad.size(); ++k) {
    CAPTURE(k);
    const auto before = crease::rt::rt_allocation_count();
    bool ok = true;
    {
      crease::rt::ScopedRtMark mark;
      ok = tracker.process(depth, bgr, *model, 1, 0, *out, {&bad[k], 1});
    }
    CHECK(crease::rt::rt_allocation_count() == before);
    CHECK(!ok);  // nothing left to register
    CHECK(out->count == 0);
    CHECK(out->cameras_ok == 0u);
    CHECK(tracker.last_bad_pose_mask() == 1u);
    CHECK(tracker.bad_pose_views() == k + 1);
  }
  // No pose span at all for a carried camera: dropped too. A good pose afterwards: back to work.
  CHECK(!tracker.process(depth, bgr, *model, 1, 0, *out));
  CHECK(tracker.bad_pose_views() == bad.size() + 1);
  CHECK(tracker.process(depth, bgr, *model, 1, 0, *out, {&t->a.poses[0], 1}));
  CHECK(out->count > 0);
  CHECK(tracker.last_bad_pose_mask() == 0u);
  CHECK(tracker.views() == views + bad.size() + 2);
}
