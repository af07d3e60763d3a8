// Plugin `camera_sim`: the simulated world's calibrated cameras, rendering the marker sheet of
// the `sheet_truth` port (the world's sheet: the `sheet_truth` plugin writes it) into the frame
// channel. It renders nothing but that sheet: until the port has a value the cameras see the
// empty table, and each frame is stamped with the time of the truth it shows.
// Parameters: cameras: DIR (cam0.yaml..), layout: layout.yaml, seed, noise, blur_px, occluders,
// frame_period_s (the stamp of frames rendered before the first truth); and camera_plugin.h's.
// Inputs: sheet_truth (crease::SheetState). Outputs: images (frames), frames (CameraFrames).
#include <memory>

#include "core/port_types/sheet_state.h"
#include "plugins/camera_rig/marker_sheet.h"
#include "plugins/cameras/camera_plugin.h"
#include "plugins/sim_world/scene/sim_source.h"
#include "rt/clock.h"
#include "rt/latest.h"

namespace {

using namespace crease::vision;

class CameraSimPlugin final : public CameraPlugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    const MarkerLayout layout = load_layout(p.get_path("layout", "markers/layout.yaml"));
    auto cams = load_camera_dir(p.get_path("cameras", "cameras"));
    const double ppm = 8.0;
    auto renderer = std::make_shared<const ViewRenderer>(
        face_texture(layout, Face::kFront, ppm), face_texture(layout, Face::kBack, ppm), ppm, cams);
    RenderOptions ro;
    ro.seed = static_cast<std::uint64_t>(p.get_in_range<int>("seed", 1, 0, 1 << 30));
    ro.noise_sigma = p.get_in_range<double>("noise", 2.0, 0.0, 50.0);
    ro.blur_sigma_px = p.get_in_range<double>("blur_px", 0.6, 0.0, 5.0);
    ro.occluders = p.get_in_range<int>("occluders", 0, 0, 10);
    const double period_s = p.get_in_range<double>("frame_period_s", 1.0 / 30, 1e-3, 10.0);
    truth_in_ = ports.latest_input<crease::SheetState>("sheet_truth");
    truth_ch_ = std::make_shared<crease::rt::LatestChannel>(sizeof(crease::SheetState));
    auto mesh_at = [ch = truth_ch_, buf = std::make_shared<crease::SheetState>()](std::uint64_t) {
      // Worker thread: the newest truth the RT side handed over (no sheet until there is one).
      if (!ch->read(buf.get(), 0).has_data()) return SheetMesh{};
      return mesh_of(*buf);
    };
    auto src = std::make_unique<SimSource>(
        renderer, mesh_at, ro, static_cast<std::int64_t>(period_s * 1e9), crease::rt::now_ns());
    configure_camera(p, ports, std::move(src));
  }

  crease::Status update(const crease::Cycle& cycle) override {
    // Hand the newest truth to the renderer before asking for the next frame.
    if (truth_in_.poll().is_new()) truth_ch_->write(&truth_in_.value(), cycle.time_ns);
    return CameraPlugin::update(cycle);
  }

 private:
  crease::LatestInput<crease::SheetState> truth_in_;
  std::shared_ptr<crease::rt::LatestChannel> truth_ch_;
};

}  // namespace

CREASE_PLUGIN(CameraSimPlugin, "camera_sim", "1.0.0")
