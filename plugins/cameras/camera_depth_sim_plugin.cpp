// Plugin `camera_depth_sim`: the simulated world's RGB-D cameras (Realsense D435-like, overhead
// and back: config/depth_cameras; D405-like on the wrists: config/wrist_cameras), rendering the
// sheet of the `sheet_truth` port into the frame channel of `depth_images` (per camera a 16-bit
// depth and a registered BGR image: plugins/camera_rig/depth_camera.h), each set announced on
// `depth_frames`. The noise model is plugins/sim_world/scene/depth_view.h (sigma = z^2 subpixel /
// (f baseline), Intel's D400 figure). Until the port has a value the cameras see the empty table.
// A camera whose calibration names a mount (plugins/camera_rig/camera_mount.h: a wrist camera) is
// rendered each frame from where the `world_shapes` port puts its mount shape; until that shape
// has been received its images are empty (the camera invalid in the set) and counted. The pose it
// was rendered from travels with its images (the set's CameraPose) to depth_tracking.
// Parameters: cameras: DIR (cam0.yaml.. with depth_unit_mm), sheet: plain | markers (layout:
// for markers), sheet_colour: {b, g, r} (plain), seed, noise (grey levels), blur_px, occluders,
// frame_period_s, depth_noise (bool), sensor: d435 | d405 (the defaults of the next six),
// baseline_mm, subpixel, max_incidence_deg, edge_jump_mm, min_range_mm, max_range_mm,
// table_z_mm, hand_height_mm (the random occluders'), world_shapes (bool, default false: the
// world's arms and hands of the `world_shapes` port at their real depth, skin-coloured; must be
// true with a carried camera); and camera_plugin.h's (`record`: a carried camera's pose per
// frame goes to camK/poses.csv, plugins/cameras/camera_source.h). Each frame set carries every
// carried camera's pose of that capture beside its images (core/frames/frame_channel.h).
// Inputs: sheet_truth (crease::SheetState), world_shapes (crease::WorldShapes, with
// `world_shapes: true`). Outputs: depth_images (frames), depth_frames; with a carried camera
// carried_unposed (crease::Figure: the share of carried cameras' frames left empty for want of
// their mount shape, %, per camera frame).
#include <cstdio>
#include <memory>

#include "core/port_types/figure.h"
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
    DepthSensorModel sm = sensor_defaults(p);
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
    for (const DepthCamera& c : cams) {
      if (!c.mount) continue;
      const std::string what = c.camera.name + " is carried (" + describe(*c.mount) + ")";
      if (!p.get<bool>("world_shapes", false))
        p.fail("world_shapes", "must be true: " + what + " and moves with the world's shapes");
    }
    truth_.bind(ports);
    shapes_.bind(p, ports);
    auto src = std::make_unique<DepthSimSource>(std::move(cams), front, back, ppm, truth_.mesh_source(), ro, sm, colour,
                                                static_cast<std::int64_t>(period_s * 1e9),
                                                crease::rt::now_ns());
    src->set_shapes_source(shapes_.shapes_source());
    source_ = src.get();  // owned by the worker until cleanup
    seen_frames_ = seen_unposed_ = 0;
    unposed_ = crease::Figure::named("camera_depth_sim carried camera frames unposed", "%",
                                     "camera frames");
    if (source_->any_carried())
      unposed_out_ = ports.latest_output<crease::Figure>("carried_unposed", unposed_);
    configure_camera(p, ports, std::move(src), true, kDepthImagesPort, kDepthFramesPort);
  }

  crease::Status update(const crease::Cycle& cycle) override {
    // Hand the newest truth to the renderer before asking for the next frame.
    truth_.forward_rt(cycle.time_ns);
    shapes_.forward_rt(cycle.time_ns);
    const crease::Status st = CameraPlugin::update(cycle);
    if (source_->any_carried()) report_carried_rt(cycle.time_ns);
    return st;
  }

  void deactivate() override {
    CameraPlugin::deactivate();
    if (source_ != nullptr && source_->any_carried())
      std::fprintf(stderr,
                   "%s: carried cameras: %llu camera frames, %llu left empty for want of their "
                   "mount shape\n",
                   instance_name().c_str(),
                   static_cast<unsigned long long>(source_->carried_frames()),
                   static_cast<unsigned long long>(source_->carried_unposed()));
  }
  void cleanup() override {
    source_ = nullptr;
    CameraPlugin::cleanup();
  }

 private:
  // The sensor's figures before the parameters' own: `sensor: d435` (default; depth_view.h) or
  // `d405` (Intel's D405 datasheet: 18 mm baseline, ideal range 7 to 50 cm).
  static DepthSensorModel sensor_defaults(const crease::Params& p) {
    DepthSensorModel sm;
    const std::string sensor = p.get<std::string>("sensor", "d435");
    if (sensor == "d405") {
      sm.baseline_mm = 18.0;
      sm.min_range_mm = 70.0;
      sm.max_range_mm = 500.0;
    } else if (sensor != "d435") {
      p.fail("sensor", "must be d435 or d405, not '" + sensor + "'");
    }
    return sm;
  }

  // RT: the carried cameras' counts into the `carried_unposed` figure when they moved.
  void report_carried_rt(std::int64_t now_ns) noexcept {
    const std::uint64_t frames = source_->carried_frames(), unposed = source_->carried_unposed();
    if (frames == seen_frames_) return;
    unposed_.set_share(frames, unposed, seen_unposed_);
    unposed_out_.write(unposed_, now_ns);
    seen_frames_ = frames;
    seen_unposed_ = unposed;
  }

  DepthSimSource* source_ = nullptr;
  crease::Figure unposed_{};
  crease::LatestOutput<crease::Figure> unposed_out_;
  std::uint64_t seen_frames_ = 0, seen_unposed_ = 0;
  SimTruthFeed truth_;
  SimShapesFeed shapes_;
};

}  // namespace

CREASE_PLUGIN(CameraDepthSimPlugin, "camera_depth_sim", "0.1.0")
