// crease-bench vision: five 1280x960 rendered views of the half-folding sheet per frame
// through (a) Crease's pipeline (fast-path detection, edge-refined corners, robust N-view
// triangulation) and (b) stock cv::aruco::detectMarkers with default parameters on full
// frames (same triangulation), in the same run. Latency is images -> key-points per frame.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core/utility.hpp>

#include "bench_registry.h"
#include "plugins/camera_rig/marker_sheet.h"
#include "plugins/sim_world/scene/synthetic_truth.h"
#include "plugins/sim_world/scene/view_renderer.h"
#include "plugins/vision/keypoint_pipeline.h"

namespace {

using namespace crease::vision;
using Clock = std::chrono::steady_clock;

double cpu_ms() {  // CPU time of the whole process (all threads), ms
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double pct(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

struct Score {
  std::vector<double> ms, cpu;
  long visible = 0, found = 0, false_ids = 0;
  double corner_se = 0;
  long corners = 0;
  double tri_se = 0;
  long tri_n = 0;
  void add_frame(const std::vector<std::vector<VisibleMarker>>& truth,
                 const std::vector<std::vector<MarkerDetection>>& dets) {
    for (std::size_t k = 0; k < truth.size(); ++k) {
      std::map<int, const VisibleMarker*> vis;
      for (const auto& v : truth[k]) vis[v.id] = &v;
      for (const auto& d : dets[k]) {
        auto it = vis.find(d.id);
        if (it == vis.end()) continue;
        ++found;
        for (int q = 0; q < 4; ++q) {
          corner_se += std::pow(cv::norm(cv::Point2d(d.corners[q]) - it->second->corners_px[q]), 2);
          ++corners;
        }
      }
      visible += static_cast<long>(truth[k].size());
    }
  }
  [[nodiscard]] double corner_rms() const { return corners ? std::sqrt(corner_se / corners) : 0; }
  [[nodiscard]] double tri_rms() const { return tri_n ? std::sqrt(tri_se / tri_n) : 0; }
  [[nodiscard]] double recall() const { return visible ? double(found) / visible : 0; }
};

// Detected ids that are not where that marker really is (wrong id or a ghost).
long false_ids(const std::vector<Camera>& cams, const SheetMesh& mesh, const MarkerLayout& L,
               const std::vector<std::vector<MarkerDetection>>& dets) {
  long bad = 0;
  for (std::size_t k = 0; k < dets.size(); ++k)
    for (const auto& d : dets[k]) {
      const int li = L.index_of(d.id);
      if (li < 0) {
        ++bad;
        continue;
      }
      const auto& m = L.markers[static_cast<std::size_t>(li)];
      cv::Point2d c, c0, seen(0, 0);
      cams[k].project(mesh.world_at(m.centre_mm.x, m.centre_mm.y), c);
      cams[k].project(mesh.world_at(m.corners_mm[0].x, m.corners_mm[0].y), c0);
      for (const auto& p : d.corners) seen += 0.25 * cv::Point2d(p);
      if (cv::norm(seen - c) > cv::norm(c0 - c) / 2) ++bad;
    }
  return bad;
}

void score_keypoints(const SheetMesh& mesh, const crease::Keypoints& kp, Score& s) {
  for (std::uint32_t i = 0; i < kp.count; ++i) {
    const auto& k = kp.points[i];
    const cv::Vec3d t = mesh.world_at(k.sheet_mm[0], k.sheet_mm[1]);
    s.tri_se += std::pow(cv::norm(cv::Vec3d(k.world_mm[0], k.world_mm[1], k.world_mm[2]) - t), 2);
    ++s.tri_n;
  }
}

// Triangulation alone: five views at 0.3 px noise, and with one outlier view in 20 % of points.
void synthetic_triangulation(const std::vector<Camera>& cams, double& clean, double& outl, double& naive) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, 0.3);
  std::uniform_real_distribution<double> u(-1, 1);
  double a = 0, b = 0, c = 0;
  const int N = 5000;
  for (int i = 0; i < N; ++i) {
    const cv::Vec3d X(100 * u(rng), 140 * u(rng), 60 + 60 * u(rng));
    ViewObservation o[kMaxViews], q[kMaxViews];
    const int bad = i % 5 == 0 ? static_cast<int>(rng() % cams.size()) : -1;
    for (std::size_t k = 0; k < cams.size(); ++k) {
      cv::Point2d px;
      cams[k].project(X, px);
      px += cv::Point2d(noise(rng), noise(rng));
      o[k] = {static_cast<int>(k), cams[k].undistort(px)};
      if (static_cast<int>(k) == bad) px += cv::Point2d(9, -12);
      q[k] = {static_cast<int>(k), cams[k].undistort(px)};
    }
    const int n = static_cast<int>(cams.size());
    TriangulatedPoint p;
    if (triangulate(cams.data(), o, n, TriangulationConfig{}, p)) a += std::pow(cv::norm(p.world_mm - X), 2);
    if (triangulate(cams.data(), q, n, TriangulationConfig{}, p)) b += std::pow(cv::norm(p.world_mm - X), 2);
    cv::Vec3d Y;
    if (triangulate_dlt(cams.data(), q, n, Y)) c += std::pow(cv::norm(Y - X), 2);
  }
  clean = std::sqrt(a / N);
  outl = std::sqrt(b / N);
  naive = std::sqrt(c / N);
}

int run_vision(int argc, char** argv) {
  int frames = 40, clutter = 1000, occluders = 1;
  DetectorConfig det_cfg;
  bool verbose = false, run_stock = true;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--frames") && i + 1 < argc) frames = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--clutter") && i + 1 < argc) clutter = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--occluders") && i + 1 < argc) occluders = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--verbose")) verbose = true;
    else if (!std::strcmp(argv[i], "--no-stock")) run_stock = false;
    else if (!std::strcmp(argv[i], "--full-every") && i + 1 < argc) det_cfg.full_search_interval = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--decimate") && i + 1 < argc) det_cfg.decimate = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--win") && i + 2 < argc) {
      det_cfg.threshold_window_min = std::atoi(argv[++i]);
      det_cfg.threshold_window_max = std::atoi(argv[++i]);
    }
    else {
      std::fprintf(stderr, "usage: crease-bench vision [--frames N] [--clutter N] [--occluders N] [--full-every N] [--decimate N] [--win MIN MAX] [--verbose] [--no-stock]\n");
      return 2;
    }
  }
  LayoutSpec spec;
  spec.double_sided = true;
  const MarkerLayout layout = make_layout(spec);
  const double ppm = 8.0;
  const auto rig = default_rig();
  const ViewRenderer renderer(face_texture(layout, Face::kFront, ppm), face_texture(layout, Face::kBack, ppm), ppm, rig);
  std::printf("vision bench: %d frames x %zu cameras 1280x960, %zu markers (%s), %d occluder(s)/view, "
              "%d OpenCV threads\n", frames, rig.size(), layout.markers.size(), layout.dictionary.c_str(),
              occluders, cv::getNumThreads());

  KeypointPipeline ours(rig, layout, det_cfg, TriangulationConfig{});
  const auto dict = dictionary_by_name(layout.dictionary);
  Score so, ss;
  long false_ours = 0, false_stock = 0;
  crease::Keypoints kp_ours, kp_stock;
  std::vector<std::vector<MarkerDetection>> stock_dets(rig.size());
  double min_px = 1e9, max_px = 0;
  for (int f = 0; f < frames; ++f) {
    // Half fold about the middle of the long edge, 0 .. 170 degrees, the sheet drifting slowly.
    const double s = frames > 1 ? double(f) / (frames - 1) : 0.0;
    const SheetMesh flat = flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {8 * s, -5 * s, 0}, 0.1 + 0.1 * s);
    const SheetMesh mesh = fold_sheet(flat, layout.sheet_h_mm / 2, 0.95 * CV_PI * s);
    std::vector<cv::Mat> imgs;
    std::vector<std::vector<VisibleMarker>> truth;
    for (int k = 0; k < static_cast<int>(rig.size()); ++k) {
      RenderOptions o;
      o.seed = static_cast<std::uint64_t>(f + 1);
      o.occluders = occluders;
      RenderedView v;
      renderer.render(k, mesh, o, v);
      imgs.push_back(v.image);
      truth.push_back(visible_markers(rig[static_cast<std::size_t>(k)], mesh, layout, v, 24.0));
      for (const auto& vm : truth.back()) {
        min_px = std::min(min_px, vm.min_side_px);
        max_px = std::max(max_px, vm.min_side_px);
      }
    }
    double c0 = cpu_ms();
    auto t0 = Clock::now();
    ours.process(imgs, f, kp_ours);
    auto t1 = Clock::now();
    so.ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    so.cpu.push_back(cpu_ms() - c0);

    c0 = cpu_ms();
    t0 = Clock::now();
    if (run_stock) cv::parallel_for_(cv::Range(0, static_cast<int>(rig.size())), [&](const cv::Range& r) {
      for (int k = r.start; k < r.end; ++k)
        detect_stock(imgs[static_cast<std::size_t>(k)], dict, stock_dets[static_cast<std::size_t>(k)]);
    }, static_cast<double>(rig.size()));
    build_keypoints(rig, layout, stock_dets, TriangulationConfig{}, kp_stock);
    t1 = Clock::now();
    ss.ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    ss.cpu.push_back(cpu_ms() - c0);

    if (verbose)
      for (std::size_t k = 0; k < truth.size(); ++k)
        for (const auto& v : truth[k]) {
          auto has = [&](const std::vector<MarkerDetection>& d) {
            return std::any_of(d.begin(), d.end(), [&](const MarkerDetection& x) { return x.id == v.id; });
          };
          if (!has(ours.detections()[k]))
            std::printf("  miss frame %d cam %zu id %d side %.1f px (stock %s)\n", f, k, v.id, v.min_side_px,
                        has(stock_dets[k]) ? "found" : "missed");
        }
    so.add_frame(truth, ours.detections());
    ss.add_frame(truth, stock_dets);
    false_ours += false_ids(rig, mesh, layout, ours.detections());
    false_stock += false_ids(rig, mesh, layout, stock_dets);
    score_keypoints(mesh, kp_ours, so);
    score_keypoints(mesh, kp_stock, ss);
  }
  std::printf("visible tags (>= 24 px): %ld, sides %.0f..%.0f px\n", so.visible, min_px, max_px);
  std::printf("%-22s %8s %8s %8s %8s %10s %8s %8s %8s\n", "", "p50_ms", "p95_ms", "cpu_ms", "recall",
              "corner_px", "tri_mm", "keypts", "false_id");
  std::printf("%-22s %8.2f %8.2f %8.2f %8.4f %10.3f %8.3f %8.1f %8ld\n", "crease (fast path)", pct(so.ms, 0.5),
              pct(so.ms, 0.95), pct(so.cpu, 0.5), so.recall(), so.corner_rms(), so.tri_rms(),
              double(so.tri_n) / frames, false_ours);
  std::printf("%-22s %8.2f %8.2f %8.2f %8.4f %10.3f %8.3f %8.1f %8ld\n", "stock detectMarkers", pct(ss.ms, 0.5),
              pct(ss.ms, 0.95), pct(ss.cpu, 0.5), ss.recall(), ss.corner_rms(), ss.tri_rms(),
              double(ss.tri_n) / frames, false_stock);
  std::printf("(latency: wall clock, images -> key-points, cameras in parallel on %d threads; cpu_ms: median CPU "
              "time per frame over all threads; stock uses the same triangulation)\n", cv::getNumThreads());

  double clean = 0, outl = 0, naive = 0;
  synthetic_triangulation(rig, clean, outl, naive);
  std::printf("triangulation, 5 views, 0.3 px noise: %.3f mm RMS; one outlier view in 20%% of points: %.3f mm "
              "(plain DLT %.3f mm)\n", clean, outl, naive);

  long clutter_false = 0;
  if (clutter > 0) {
    DetectorConfig cfg;
    cfg.max_id = layout.max_id();
    for (int i = 0; i < clutter; ++i) {
      MarkerDetector det(cfg);
      std::vector<MarkerDetection> out;
      det.detect(render_clutter(1280, 960, static_cast<std::uint64_t>(i) + 1000u, layout.max_id()), out);
      clutter_false += static_cast<long>(out.size());
    }
    std::printf("clutter: %ld false marker ids over %d frames\n", clutter_false, clutter);
  }
  const double op95 = pct(so.ms, 0.95), sp95 = pct(ss.ms, 0.95);
  std::printf("vision: ours_p95_ms=%.2f stock_p95_ms=%.2f speedup=%.2f recall=%.4f corner_rms_px=%.3f "
              "tri_rms_mm=%.3f ours_cpu_ms=%.2f stock_cpu_ms=%.2f stock_recall=%.4f stock_corner_rms_px=%.3f "
              "tri_synth_rms_mm=%.3f tri_outlier_rms_mm=%.3f clutter_false_ids=%ld\n",
              op95, sp95, sp95 / op95, so.recall(), so.corner_rms(), so.tri_rms(), pct(so.cpu, 0.5), pct(ss.cpu, 0.5),
              ss.recall(), ss.corner_rms(), clean, outl, clutter_false);
  return 0;
}

}  // namespace

CREASE_BENCH(vision, "five 1280x960 cameras: marker detection + triangulation vs stock cv::aruco", run_vision);
