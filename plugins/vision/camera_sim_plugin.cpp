// Plugin `camera_sim`: synthetic cameras rendering the marker sheet into the frame channel.
// Parameters: cameras: DIR (cam0.yaml..), layout: layout.yaml, truth: builtin | port (render
// the mesh of the `sheet_truth` port, frames stamped with the truth's time; builtin: an
// analytic half fold of its own with fold_start_s, fold_duration_s, fold_angle_deg), seed,
// noise, blur_px, occluders, frame_period_s; and camera_plugin.h's.
// Inputs: sheet_truth (crease::SheetState, truth: port). Outputs: frames (crease::CameraFrames).
#include <algorithm>
#include <functional>

#include "camera_plugin.h"
#include "core/port_types/sheet_state.h"
#include "marker_sheet.h"
#include "rt/clock.h"
#include "rt/latest.h"

namespace {

using namespace crease::vision;

class CameraSimPlugin final : public CameraPlugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    const MarkerLayout layout =
        load_layout(p.get_path("layout", "markers/layout.yaml"));
    auto cams = load_camera_dir(p.get_path("cameras", "cameras"));
    const double ppm = 8.0;
    auto renderer = std::make_shared<const ViewRenderer>(
        face_texture(layout, Face::kFront, ppm), face_texture(layout, Face::kBack, ppm), ppm, cams);
    RenderOptions ro;
    ro.seed = static_cast<std::uint64_t>(p.get_in_range<int>("seed", 1, 0, 1 << 30));
    ro.noise_sigma = p.get_in_range<double>("noise", 2.0, 0.0, 50.0);
    ro.blur_sigma_px = p.get_in_range<double>("blur_px", 0.6, 0.0, 5.0);
    ro.occluders = p.get_in_range<int>("occluders", 0, 0, 10);
    const std::string truth = p.get<std::string>("truth", "builtin");
    const double t0 = p.get_in_range<double>("fold_start_s", 1.0, 0.0, 1e6);
    const double dur = p.get_in_range<double>("fold_duration_s", 4.0, 0.01, 1e6);
    const double angle =
        p.get_in_range<double>("fold_angle_deg", 170.0, 0.0, 180.0) * CV_PI / 180.0;
    const double period_s = p.get_in_range<double>("frame_period_s", 1.0 / 30, 1e-3, 10.0);
    const SheetMesh flat = flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0}, 0.1);
    const double h = layout.sheet_h_mm;
    std::function<SheetMesh(std::uint64_t)> mesh_at = [=](std::uint64_t i) {
      const double s = std::clamp((double(i) * period_s - t0) / dur, 0.0, 1.0);
      return fold_sheet(flat, h / 2, angle * s);
    };
    if (truth == "port") {
      truth_in_ = ports.latest_input<crease::SheetState>("sheet_truth");
      truth_ch_ = std::make_shared<crease::rt::LatestChannel>(sizeof(crease::SheetState));
      mesh_at = [ch = truth_ch_, buf = std::make_shared<crease::SheetState>(),
                 fallback = flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0},
                                       0.0)](std::uint64_t) {
        // Worker thread: the newest truth the RT side handed over (flat until there is one).
        if (!ch->read(buf.get(), 0).has_data() || buf->nodes_u < 2 || buf->nodes_v < 2)
          return fallback;
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
    auto src = std::make_unique<SimSource>(
        renderer, mesh_at, ro, static_cast<std::int64_t>(period_s * 1e9), crease::rt::now_ns());
    configure_camera(p, ports, std::move(src));
  }

  crease::Status update(const crease::Cycle& cycle) override {
    // Hand the newest truth to the renderer before asking for the next frame.
    if (truth_in_.bound() && truth_in_.poll().is_new()) truth_ch_->write(&truth_in_.value(), cycle.time_ns);
    return CameraPlugin::update(cycle);
  }

 private:
  crease::LatestInput<crease::SheetState> truth_in_;
  std::shared_ptr<crease::rt::LatestChannel> truth_ch_;
};

}  // namespace

CREASE_PLUGIN(CameraSimPlugin, "camera_sim", "1.0.0")
