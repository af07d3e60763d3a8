// Plugin `camera_sim`: the simulated world's calibrated cameras, rendering the marker sheet of
// the `sheet_truth` port (the world's sheet: the `sheet_truth` plugin writes it) into the frame
// channel. It renders nothing but that sheet: until the port has a value the cameras see the
// empty table, and each frame is stamped with the time of the truth it shows.
// Parameters: cameras: DIR (cam0.yaml..), layout: layout.yaml, seed, noise, blur_px, occluders,
// frame_period_s (the stamp of frames rendered before the first truth); dropouts, dropout_frames,
// dropout_from_frame, dropout_to_frame, dropout_seed (cameras that deliver nothing for a run of
// frame sets: sim_source.h); world_shapes (bool, default false: draw the world's arms and hands
// of the `world_shapes` port, their real geometry, as skin-coloured occluders depth-tested
// against the sheet; `occluders` are random hand-like ones, for the tracking benchmarks); and
// camera_plugin.h's.
// Inputs: sheet_truth (crease::SheetState), world_shapes (crease::WorldShapes, with
// `world_shapes: true`). Outputs: images (frames), frames (CameraFrames).
#include <memory>

#include "core/port_types/sheet_state.h"
#include "plugins/camera_rig/marker_sheet.h"
#include "plugins/cameras/camera_plugin.h"
#include "plugins/cameras/sim_truth_feed.h"
#include "plugins/sim_world/scene/sim_source.h"
#include "rt/clock.h"

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
    const RenderOptions ro = read_render_options(p);
    const double period_s = p.get_in_range<double>("frame_period_s", 1.0 / 30, 1e-3, 10.0);
    // Camera dropouts (crease-trials --faults): `dropouts` of `dropout_frames` frame sets each.
    const int dropouts = p.get_in_range<int>("dropouts", 0, 0, 100);
    const auto dropout_frames = static_cast<std::uint64_t>(p.get_in_range<int>("dropout_frames", 8, 1, 100000));
    const auto from = static_cast<std::uint64_t>(p.get_in_range<int>("dropout_from_frame", 30, 0, 100000000));
    const auto to = static_cast<std::uint64_t>(
        p.get_in_range<int>("dropout_to_frame", 450, static_cast<int>(from), 100000000));
    const auto dropout_seed = static_cast<std::uint64_t>(
        p.get_in_range<long long>("dropout_seed", static_cast<long long>(ro.seed), 0, (1LL << 62)));
    auto drops = draw_dropouts(dropout_seed, dropouts, dropout_frames, from, to, static_cast<int>(cams.size()));
    truth_.bind(ports);
    shapes_.bind(p, ports);
    auto src = std::make_unique<SimSource>(renderer, truth_.mesh_source(), ro, static_cast<std::int64_t>(period_s * 1e9),
                                           crease::rt::now_ns(), std::move(drops));
    src->set_shapes_source(shapes_.shapes_source());
    configure_camera(p, ports, std::move(src));
  }

  crease::Status update(const crease::Cycle& cycle) override {
    // Hand the newest truth to the renderer before asking for the next frame.
    truth_.forward_rt(cycle.time_ns);
    shapes_.forward_rt(cycle.time_ns);
    return CameraPlugin::update(cycle);
  }

 private:
  SimTruthFeed truth_;
  SimShapesFeed shapes_;
};

}  // namespace

CREASE_PLUGIN(CameraSimPlugin, "camera_sim", "1.0.0")
