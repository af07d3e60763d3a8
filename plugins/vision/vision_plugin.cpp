// Plugin `vision`: camera source (sim / replay / v4l2) -> marker detection -> N-view
// triangulation -> `keypoints` port. One plugin owns the sources as library objects: camera
// images never cross a port (a fixed-capacity payload for five 1280x960 images would be 6 MB
// copied per frame); only the key-points do. Capture and processing run on a worker thread
// (VisionWorker); update() only hands frames over, so it neither allocates nor blocks.
//
// Parameters (paths relative to the configuration file's folder):
//   source: sim | replay | v4l2          cameras: DIR of cam0.yaml..   layout: layout.yaml
//   replay_dir: DIR (replay)             devices: [/dev/video0, ...] (v4l2)
//   record: DIR (optional, any source: writes the replay layout)
//   sim: seed, noise, blur_px, occluders, fold_start_s, fold_duration_s, fold_angle_deg
//   detector: decimate, full_search_interval;  max_reproj_px, refine
// Outputs: keypoints (crease::Keypoints). Status: degraded when a camera delivered nothing,
// no new frame came for `stale_cycles` cycles, or a replay ended; fault if the worker failed.
#include <filesystem>
#include <memory>
#include <string>

#include "core/plugin.h"
#include "core/port_types/keypoints.h"
#include "rt/clock.h"
#include "marker_sheet.h"
#include "vision_worker.h"

namespace {

using namespace crease::vision;

class VisionPlugin final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    const std::filesystem::path base = std::filesystem::path(p.file()).parent_path();
    auto path = [&](const std::string& v) { return std::filesystem::path(v).is_absolute() ? v : (base / v).string(); };
    const std::string source = p.get<std::string>("source", "sim");
    const MarkerLayout layout = load_layout(path(p.get<std::string>("layout", "markers/layout.yaml")));
    DetectorConfig det;
    det.decimate = p.get_in_range<int>("decimate", 2, 1, 4);
    det.full_search_interval = p.get_in_range<int>("full_search_interval", 8, 1, 1000);
    TriangulationConfig tri;
    tri.max_reproj_px = p.get_in_range<double>("max_reproj_px", 2.0, 0.1, 50.0);
    tri.refine = p.get<bool>("refine", true);
    stale_cycles_ = p.get_in_range<int>("stale_cycles", 10, 1, 100000);

    std::unique_ptr<CameraSource> src;
    if (source == "sim") {
      auto cams = load_camera_dir(path(p.get<std::string>("cameras", "cameras")));
      const double ppm = 8.0;
      auto renderer = std::make_shared<const ViewRenderer>(face_texture(layout, Face::kFront, ppm),
                                                           face_texture(layout, Face::kBack, ppm), ppm, cams);
      RenderOptions ro;
      ro.seed = static_cast<std::uint64_t>(p.get_in_range<int>("seed", 1, 0, 1 << 30));
      ro.noise_sigma = p.get_in_range<double>("noise", 2.0, 0.0, 50.0);
      ro.blur_sigma_px = p.get_in_range<double>("blur_px", 0.6, 0.0, 5.0);
      ro.occluders = p.get_in_range<int>("occluders", 0, 0, 10);
      // Built-in analytic half fold until the sheet_truth port exists (see README).
      const double t0 = p.get_in_range<double>("fold_start_s", 1.0, 0.0, 1e6);
      const double dur = p.get_in_range<double>("fold_duration_s", 4.0, 0.01, 1e6);
      const double angle = p.get_in_range<double>("fold_angle_deg", 170.0, 0.0, 180.0) * CV_PI / 180.0;
      const double period_s = p.get_in_range<double>("frame_period_s", 1.0 / 30, 1e-3, 10.0);
      const SheetMesh flat = flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0}, 0.1);
      const double h = layout.sheet_h_mm;
      auto mesh_at = [=](std::uint64_t i) {
        const double s = std::clamp((double(i) * period_s - t0) / dur, 0.0, 1.0);
        return fold_sheet(flat, h / 2, angle * s);
      };
      src = std::make_unique<SimSource>(renderer, mesh_at, ro, static_cast<std::int64_t>(period_s * 1e9),
                                        crease::rt::now_ns());
    } else if (source == "replay") {
      src = std::make_unique<ReplaySource>(path(p.get<std::string>("replay_dir")));
    } else if (source == "v4l2") {
      auto cams = load_camera_dir(path(p.get<std::string>("cameras", "cameras")));
      std::vector<std::string> devices;
      const YAML::Node d = p.raw("devices");
      if (!d || !d.IsSequence()) p.fail("devices", "expected a list of video devices");
      for (const auto& n : d) devices.push_back(n.as<std::string>());
      src = std::make_unique<V4l2Source>(std::move(cams), devices);
    } else {
      p.fail("source", "expected sim, replay or v4l2, got '" + source + "'");
    }
    const std::string record = p.has("record") ? path(p.get<std::string>("record")) : std::string();
    buf_ = std::make_unique<crease::Keypoints>();
    out_ = ports.latest_output<crease::Keypoints>("keypoints", crease::Keypoints{});
    worker_ = std::make_unique<VisionWorker>(std::move(src), layout, det, tri, record);
  }

  crease::Status update(const crease::Cycle& cycle) override {
    switch (worker_->take_and_request_rt(*buf_)) {
      case VisionWorker::Take::fresh:
        out_.write(*buf_, cycle.time_ns);
        since_fresh_ = 0;
        return buf_->cameras_ok == worker_->all_cameras_mask() ? crease::Status::ok : crease::Status::degraded;
      case VisionWorker::Take::none:
        return ++since_fresh_ > stale_cycles_ ? crease::Status::degraded : crease::Status::ok;
      case VisionWorker::Take::ended:
        return crease::Status::degraded;
      case VisionWorker::Take::failed:
        log_rt(crease::rt::LogLevel::error, "vision worker failed (see host log)");
        return crease::Status::fault;
    }
    return crease::Status::fault;
  }

  void cleanup() override { worker_.reset(); }

 private:
  std::unique_ptr<VisionWorker> worker_;
  std::unique_ptr<crease::Keypoints> buf_;
  crease::LatestOutput<crease::Keypoints> out_;
  int stale_cycles_ = 10;
  int since_fresh_ = 0;
};

}  // namespace

CREASE_PLUGIN(VisionPlugin, "vision", "1.0.0")
