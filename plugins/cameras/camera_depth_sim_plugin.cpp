// Plugin `camera_depth_sim`: the simulated world's RGB-D cameras (Realsense D435-like, overhead
// and back: config/depth_cameras), rendering the sheet of the `sheet_truth` port into the frame
// channel of `depth_images` (per camera a 16-bit depth and a registered BGR image:
// plugins/camera_rig/depth_camera.h), each set announced on `depth_frames`. The noise model is
// plugins/sim_world/scene/depth_view.h (sigma = z^2 subpixel / (f baseline), Intel's D400 figure).
// Until the port has a value the cameras see the empty table.
// Parameters: cameras: DIR (cam0.yaml.. with depth_unit_mm), sheet: plain | markers (layout:
// for markers), sheet_colour: {b, g, r} (plain), seed, noise (grey levels), blur_px, occluders,
// frame_period_s, depth_noise (bool), baseline_mm, subpixel, max_incidence_deg, edge_jump_mm,
// min_range_mm, max_range_mm, table_z_mm, hand_height_mm (the random occluders'), world_shapes
// (bool, default false: the world's arms and hands of the `world_shapes` port at their real
// depth, skin-coloured); and camera_plugin.h's (no `record`: depth has no replay layout yet).
// Inputs: sheet_truth (crease::SheetState), world_shapes (crease::WorldShapes, with
// `world_shapes: true`). Outputs: depth_images (frames), depth_frames.
#include <memory>

#include "core/port_types/sheet_state.h"
#include "plugins/camera_rig/depth_camera.h"
#include "plugins/camera_rig/marker_sheet.h"
#include "plugins/cameras/camera_plugin.h"
#include "plugins/cameras/sim_truth_feed.h"
#include "plugins/sim_world/scene/depth_sim_source.h"
#include "rt/clock.h"

namespace {

using namespace crease::vision;

class CameraDepthSimPlugin final : public CameraPlugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    auto cams = load_depth_camera_dir(p.get_path("cameras", "depth_cameras"));
    const std::string sheet = p.get<std::string>("sheet", "plain");
    DepthColourModel colour;
    cv::Mat front, back;
    double ppm = 1.0;
    if (sheet == "plain") {
      const crease::Params c = p.child("sheet_colour");
      colour.sheet_bgr = cv::Vec3b(static_cast<std::uint8_t>(c.get_in_range<int>("b", 200, 0, 255)),
                                   static_cast<std::uint8_t>(c.get_in_range<int>("g", 140, 0, 255)),
                                   static_cast<std::uint8_t>(c.get_in_range<int>("r", 40, 0, 255)));
      front = back = DepthSimSource::plain_texture(400.0, 400.0, ppm);
    } else if (sheet == "markers") {
      colour.plain = false;
      ppm = 8.0;
      const MarkerLayout layout = load_layout(p.get_path("layout", "markers/layout.yaml"));
      front = face_texture(layout, Face::kFront, ppm);
      back = face_texture(layout, Face::kBack, ppm);
    } else {
      p.fail("sheet", "must be plain or markers, not '" + sheet + "'");
    }
    const RenderOptions ro = read_render_options(p);
    DepthSensorModel sm;
    sm.noise = p.get<bool>("depth_noise", true);
    sm.baseline_mm = p.get_in_range<double>("baseline_mm", sm.baseline_mm, 1.0, 1000.0);
    sm.subpixel = p.get_in_range<double>("subpixel", sm.subpixel, 0.0, 2.0);
    sm.max_incidence_deg = p.get_in_range<double>("max_incidence_deg", sm.max_incidence_deg, 1.0, 90.0);
    sm.edge_jump_mm = p.get_in_range<double>("edge_jump_mm", sm.edge_jump_mm, 0.1, 1e4);
    sm.min_range_mm = p.get_in_range<double>("min_range_mm", sm.min_range_mm, 0.0, 1e5);
    sm.max_range_mm = p.get_in_range<double>("max_range_mm", sm.max_range_mm, sm.min_range_mm, 1e5);
    sm.table_z_mm = p.get_in_range<double>("table_z_mm", sm.table_z_mm, -1e4, 1e4);
    sm.hand_height_mm = p.get_in_range<double>("hand_height_mm", sm.hand_height_mm, 0.0, 1e3);
    const double period_s = p.get_in_range<double>("frame_period_s", 1.0 / 30, 1e-3, 10.0);
    truth_.bind(ports);
    shapes_.bind(p, ports);
    auto src = std::make_unique<DepthSimSource>(std::move(cams), front, back, ppm, truth_.mesh_source(), ro, sm, colour,
                                                static_cast<std::int64_t>(period_s * 1e9),
                                                crease::rt::now_ns());
    src->set_shapes_source(shapes_.shapes_source());
    configure_camera(p, ports, std::move(src), true, kDepthImagesPort, kDepthFramesPort);
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

CREASE_PLUGIN(CameraDepthSimPlugin, "camera_depth_sim", "0.1.0")
