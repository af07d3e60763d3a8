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
#include <functional>
#include <memory>
#include <string>

#include "core/plugin.h"
#include "core/port_types/keypoints.h"
#include "core/port_types/sheet_state.h"
#include "rt/latest.h"
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
      const std::string truth = p.get<std::string>("truth", "builtin");
      // The sheet to render: `port` takes it from the `sheet_truth` port (the simulated world);
      // `builtin` is an analytic half fold of its own (no other plugin needed).
      const double t0 = p.get_in_range<double>("fold_start_s", 1.0, 0.0, 1e6);
      const double dur = p.get_in_range<double>("fold_duration_s", 4.0, 0.01, 1e6);
      const double angle = p.get_in_range<double>("fold_angle_deg", 170.0, 0.0, 180.0) * CV_PI / 180.0;
      const double period_s = p.get_in_range<double>("frame_period_s", 1.0 / 30, 1e-3, 10.0);
      const SheetMesh flat = flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0}, 0.1);
      const double h = layout.sheet_h_mm;
      std::function<SheetMesh(std::uint64_t)> mesh_at = [=](std::uint64_t i) {
        const double s = std::clamp((double(i) * period_s - t0) / dur, 0.0, 1.0);
        return fold_sheet(flat, h / 2, angle * s);
      };
      if (truth == "port") {
        truth_in_ = ports.latest_input<crease::SheetState>("sheet_truth");
        truth_buf_ = std::make_unique<crease::SheetState>();
        truth_ch_ = std::make_shared<crease::rt::LatestChannel>(sizeof(crease::SheetState));
        mesh_at = [ch = truth_ch_, buf = std::make_shared<crease::SheetState>(),
                   fallback = flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0}, 0.0)](std::uint64_t) {
          // Worker thread: the newest truth the RT side handed over (flat until there is one).
          if (!ch->read(buf.get(), 0).has_data() || buf->nodes_u < 2 || buf->nodes_v < 2) return fallback;
          SheetMesh m;
          m.nx = buf->nodes_u;
          m.ny = buf->nodes_v;
          m.w_mm = buf->width_mm;
          m.h_mm = buf->height_mm;
          m.timestamp_ns = buf->timestamp_ns;
          m.nodes.resize(static_cast<std::size_t>(m.nx) * m.ny);
          for (std::size_t k = 0; k < m.nodes.size(); ++k) {
            m.nodes[k] = {buf->position_mm[k][0], buf->position_mm[k][1], buf->position_mm[k][2]};
          }
          return m;
        };
      } else if (truth != "builtin") {
        p.fail("truth", "expected builtin or port, got '" + truth + "'");
      }
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
    if (truth_in_.bound() && truth_in_.read(*truth_buf_).is_new()) truth_ch_->write(truth_buf_.get(), cycle.time_ns);
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
  // truth: port — the sheet_truth input, and the hand-over to the worker's renderer.
  crease::LatestInput<crease::SheetState> truth_in_;
  std::unique_ptr<crease::SheetState> truth_buf_;
  std::shared_ptr<crease::rt::LatestChannel> truth_ch_;
  int stale_cycles_ = 10;
  int since_fresh_ = 0;
};

}  // namespace

CREASE_PLUGIN(VisionPlugin, "vision", "1.0.0")
