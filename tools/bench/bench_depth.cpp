// crease-bench depth: the depth path of issue 17 per frame, on the simulated D435s of
// config/depth_cameras (848x480) watching a plain sheet play the half fold (175 deg in 5 s,
// then held), frame by frame at 30 Hz of the fold's time:
//  - ours: DepthTracker (mask + back-projection + voxels; model visibility; the sheet-kernel
//    CPD: low rank, Woodbury M-step, truncated grid E-step over the visible nodes) in a closed
//    loop with the XPBD sheet model (two 1/60 s steps per frame, the fold's crease announced when
//    it starts, as the folding sequence does);
//  - the alternative on the same clouds and the same warm starts: a dense textbook non-rigid
//    CPD (tests/plugins/depth_tracking/dense_cpd_reference.h: full M x N posteriors, M x M LU
//    M-step, kernel from the centroids' world positions, every node a centroid), every Kth
//    frame; also our textbook form (cpd.h: exp cut-off, M x M Cholesky).
// Registration error: mean distance of the registered nodes to the truth, over the nodes ours
// saw (the others ours does not target). Tracking error: the closed-loop model against the
// truth, from the fold's start. The tracker runs here without the loops' latency (a frame's
// targets reach the model before its next step): the plugin test measures it in real loops.
// Rendering is not timed. The machine is shared: times are noisy; both solvers run in turn.
// Then (bench_depth_loop.cpp; --no-fused skips it) the printed sheet in the same loop: the five
// colour cameras' key-points alone, and fused with the depth path (err_fused_mm).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "bench_registry.h"
#include "core/port_types/depth_targets.h"
#include "plugins/depth_tracking/cpd.h"
#include "plugins/depth_tracking/depth_tracker.h"
#include "plugins/sheet_model/sheet_runner.h"
#include "plugins/sim_world/scene/depth_sim_source.h"
#include "plugins/sim_world/scene/fold_script.h"
#include "rt/clock.h"
#include "tests/plugins/depth_tracking/dense_cpd_reference.h"
#include "tools/bench/bench_depth_loop.h"

using namespace crease;

namespace {

double pct(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

int run_depth(int argc, char** argv) {
  int dense_every = 10;
  double end_s = 7.0;
  bool predict = false, along_normal = true, trace = false, fused = true;
  int rank = 60, iterations = 15;
  double voxel = 6.0, cut = 20.0, tangential = 0.3;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--dense-every") && i + 1 < argc) {
      dense_every = std::max(1, std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--seconds") && i + 1 < argc) {
      end_s = std::max(1.0, std::atof(argv[++i]));
    } else if (!std::strcmp(argv[i], "--no-dense")) {
      dense_every = 1 << 30;
    } else if (!std::strcmp(argv[i], "--predict")) {
      predict = true;
    } else if (!std::strcmp(argv[i], "--3d-springs")) {
      along_normal = false;
    } else if (!std::strcmp(argv[i], "--trace")) {
      trace = true;
    } else if (!std::strcmp(argv[i], "--no-fused")) {
      fused = false;
    } else if (!std::strcmp(argv[i], "--rank") && i + 1 < argc) {
      rank = std::max(1, std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--iterations") && i + 1 < argc) {
      iterations = std::max(1, std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--voxel") && i + 1 < argc) {
      voxel = std::max(0.5, std::atof(argv[++i]));
    } else if (!std::strcmp(argv[i], "--tangential") && i + 1 < argc) {
      tangential = std::clamp(std::atof(argv[++i]), 0.0, 1.0);
    } else if (!std::strcmp(argv[i], "--cut") && i + 1 < argc) {
      cut = std::clamp(std::atof(argv[++i]), 4.0, 700.0);
    } else {
      std::fprintf(
          stderr,
          "usage: crease-bench depth [--dense-every K | --no-dense] [--seconds S] [--predict] "
          "[--3d-springs] [--trace] [--no-fused] [--rank K] [--iterations N] [--voxel MM] [--cut "
          "E] [--tangential T]\n");
      return 2;
    }
  }
  const std::string src = CREASE_SOURCE_DIR;
  const auto cams = vision::load_depth_camera_dir(src + "/config/depth_cameras");
  sheet::SheetParams sp;
  sp.grid.origin_mm = {-105.0, 148.5, 0.5 * sp.grid.thickness_mm};
  sp.solver.depth_along_normal = along_normal;
  sp.solver.depth_tangential_weight = tangential;
  const double start_s = 0.5;
  const auto script = sheet::FoldScript::half_fold(sp.grid);
  const int W = sp.grid.nodes_u, H = sp.grid.nodes_v, M = W * H;
  std::vector<sheet::Vec3> truth(static_cast<std::size_t>(M));
  double t_now = 0.0;
  const auto mesh_at = [&](std::uint64_t) {
    script.node_positions(std::max(0.0, t_now - start_s), truth);
    return bench::mesh_of(sp, truth);
  };
  const cv::Mat tex = vision::DepthSimSource::plain_texture(400, 400, 1.0);
  vision::RenderOptions ro;
  ro.noise_sigma = 1.0;
  vision::DepthSimSource source(cams, tex, tex, 1.0, mesh_at, ro, vision::DepthSensorModel{},
                                vision::DepthColourModel{}, 33'333'333);

  depth::TrackerParams tp;
  tp.cloud.mask = {95, 115, 120, 255, 40, 255};
  tp.cloud.voxel_mm = voxel;
  tp.cpd.max_iterations = iterations;
  tp.kernel_rank = rank;
  tp.kernel_cut = cut;
  tp.cpd.sigma2_init_mm2 = 25.0;
  tp.cpd.sigma2_min_mm2 = 2.0;
  depth::DepthTracker tracker;
  tracker.configure(tp, cams);
  depth::NonRigidCpd textbook;
  textbook.configure(tp.cpd, M, tp.max_points);

  sheet::SheetRunner runner(sp, 0.0);
  runner.set_depth_prediction(predict);
  auto state = std::make_unique<SheetState>();
  auto targets = std::make_unique<DepthTargets>();
  std::int64_t now_ns = 1'000'000'000;
  (void)runner.step_rt(1.0 / 60, now_ns, *state);
  bool creased = false;

  std::vector<double> cloud_ms, cpd_ms, path_ms, dense_ms, textbook_ms, track_err;
  std::vector<double> ours_reg, dense_reg, textbook_reg;
  std::size_t cloud_points = 0;
  const int frames = static_cast<int>(end_s * 30.0);
  std::printf("depth bench: %zu D435 cameras 848x480, plain sheet, half fold, %d frames at 30 Hz, dense reference "
              "every %d\n",
              cams.size(), frames, dense_every);
  vision::Frame f;
  std::vector<cv::Mat> depth_im(cams.size()), bgr_im(cams.size());
  std::vector<Eigen::Vector3d> y0(static_cast<std::size_t>(M)), yt(static_cast<std::size_t>(M));
  for (int i = 0; i < frames; ++i) {
    t_now = i / 30.0;
    if (!creased && t_now >= start_s) {  // the sequence announces the crease as the fold starts
      runner.apply(bench::half_fold_crease(sp));
      creased = true;
    }
    (void)source.grab(f);
    for (std::size_t k = 0; k < cams.size(); ++k) {
      depth_im[k] = f.images[2 * k];
      bgr_im[k] = f.images[2 * k + 1];
    }
    (void)tracker.process(depth_im, bgr_im, *state, now_ns, static_cast<std::uint64_t>(i), *targets);
    const auto& tm = tracker.timing();
    cloud_ms.push_back(double(tm.cloud_ns) * 1e-6);
    cpd_ms.push_back(double(tm.cpd_ns) * 1e-6);
    path_ms.push_back(double(tm.cloud_ns + tm.cpd_ns) * 1e-6);
    cloud_points = std::max(cloud_points, tracker.cloud().points().size());
    // Registration error over the nodes ours saw (truth at this frame's time).
    const auto reg_err = [&](std::span<const Eigen::Vector3d> y) {
      double s = 0;
      int n = 0;
      for (int k = 0; k < M; ++k) {
        if (!tracker.active()[static_cast<std::size_t>(k)]) continue;
        const auto& p = truth[static_cast<std::size_t>(k)];
        s += (y[static_cast<std::size_t>(k)] - Eigen::Vector3d(p.x, p.y, p.z)).norm();
        ++n;
      }
      return n > 0 ? s / n : 0.0;
    };
    const bool compare = i % dense_every == 0 && !tracker.cloud().points().empty() && tracker.last_cpd().ok;
    if (compare) {
      ours_reg.push_back(reg_err(tracker.registered()));
      for (int k = 0; k < M; ++k)
        y0[static_cast<std::size_t>(k)] =
            Eigen::Vector3d(state->position_mm[k][0], state->position_mm[k][1], state->position_mm[k][2]);
      const auto cloud = tracker.cloud().points();
      std::int64_t t0 = rt::now_ns();
      (void)textbook.register_cloud(y0, cloud, yt);
      textbook_ms.push_back(double(rt::now_ns() - t0) * 1e-6);
      textbook_reg.push_back(reg_err(yt));
      Eigen::MatrixXd x(static_cast<Eigen::Index>(cloud.size()), 3), y0m(M, 3);
      for (std::size_t j = 0; j < cloud.size(); ++j) x.row(static_cast<Eigen::Index>(j)) = cloud[j].transpose();
      for (int k = 0; k < M; ++k) y0m.row(k) = y0[static_cast<std::size_t>(k)].transpose();
      t0 = rt::now_ns();
      const auto d = depth::test::dense_cpd(x, y0m, tp.cpd);
      dense_ms.push_back(double(rt::now_ns() - t0) * 1e-6);
      for (int k = 0; k < M; ++k) yt[static_cast<std::size_t>(k)] = d.y.row(k).transpose();
      dense_reg.push_back(reg_err(yt));
    }
    runner.set_depth_targets(*targets);
    for (int s = 0; s < 2; ++s) {
      now_ns += 16'666'667;
      (void)runner.step_rt(1.0 / 60, now_ns, *state);
    }
    if (t_now >= start_s) {
      // The model after this frame's steps against the truth at the same time.
      script.node_positions(std::max(0.0, t_now + 1.0 / 30 - start_s), truth);
      double e = 0, e_flap = 0, e_lower = 0;
      for (int k = 0; k < M; ++k) {
        const auto& p = truth[static_cast<std::size_t>(k)];
        const double d =
            std::hypot(state->position_mm[k][0] - p.x, state->position_mm[k][1] - p.y, state->position_mm[k][2] - p.z);
        e += d;
        (k / W < H / 2 ? e_flap : e_lower) += d;
      }
      track_err.push_back(e / M);
      if (trace && i % 15 == 0)
        std::printf("  t %.2f s: model error %.2f mm (flap %.2f, lower %.2f), %u targets, %u visible, %zu points, "
                    "%d iterations, sigma2 %.1f\n",
                    t_now, e / M, e_flap / (W * (H / 2)), e_lower / (M - W * (H / 2)), targets->count, targets->visible_nodes, tracker.cloud().points().size(),
                    tracker.last_cpd().iterations, tracker.last_cpd().sigma2_mm2);
    }
  }
  std::printf("%-40s %9s %9s %9s\n", "per frame", "p50_ms", "p95_ms", "reg_mm");
  std::printf("%-40s %9.2f %9.2f %9s\n", "ours: cloud (mask, back-projection, voxels)", pct(cloud_ms, 0.5),
              pct(cloud_ms, 0.95), "");
  std::printf("%-40s %9.2f %9.2f %9.2f\n", "ours: CPD (visibility + sheet-kernel CPD)", pct(cpd_ms, 0.5),
              pct(cpd_ms, 0.95), mean(ours_reg));
  std::printf("%-40s %9.2f %9.2f %9s\n", "ours: whole depth path", pct(path_ms, 0.5), pct(path_ms, 0.95), "");
  std::printf("%-40s %9.2f %9.2f %9.2f\n", "textbook CPD, cut-off (cpd.h)", pct(textbook_ms, 0.5),
              pct(textbook_ms, 0.95), mean(textbook_reg));
  std::printf("%-40s %9.2f %9.2f %9.2f\n", "dense textbook CPD (reference)", pct(dense_ms, 0.5), pct(dense_ms, 0.95),
              mean(dense_reg));
  const double speedup = pct(dense_ms, 0.5) / std::max(1e-9, pct(cpd_ms, 0.5));
  const double worst = track_err.empty() ? 0.0 : *std::max_element(track_err.begin(), track_err.end());
  std::printf("largest cloud %zu points, %zu frames compared; tracking error from the fold's start: mean %.2f mm, "
              "worst frame %.2f mm, end %.2f mm\n",
              cloud_points, dense_ms.size(), mean(track_err), worst, track_err.empty() ? 0.0 : track_err.back());
  char fused_mm[32] = "na";
  if (fused) {
    // The printed sheet: the five colour cameras' key-points alone, then with the depth path.
    bench::LoopSetup fs;
    fs.sheet = sp;
    fs.scene = bench::script_feed(script, sp, start_s);
    fs.crease_s = start_s;
    fs.end_s = end_s;
    fs.depth = tp;
    const auto row = [](const char* what, const bench::TrackingError& e) {
      std::printf(
          "printed sheet, %-22s tracking error mean %.2f mm, worst frame %.2f mm, end %.2f mm; %d "
          "marker "
          "sets, %.0f key-points each\n",
          what, e.mean_mm, e.worst_mm, e.end_mm, e.keypoint_sets, e.keypoints_mean);
    };
    const bench::TrackingError m = bench::track_sheet(fs, false, true);
    row("markers alone:", m);
    const bench::TrackingError md = bench::track_sheet(fs, true, true);
    row("markers + depth:", md);
    std::snprintf(fused_mm, sizeof fused_mm, "%.2f", md.mean_mm);
  }
  std::printf(
      "depth: path_p95_ms=%.2f cpd_ms=%.2f dense_cpd_ms=%.2f speedup=%.1f err_mm=%.2f "
      "err_fused_mm=%s\n",
      pct(path_ms, 0.95), pct(cpd_ms, 0.5), pct(dense_ms, 0.5), speedup, mean(track_err), fused_mm);
  return 0;
}

}  // namespace

CREASE_BENCH(depth, "depth path per frame (cloud + CPD) vs a dense textbook CPD, and the tracking error", run_depth);
