// Plugin `camera_depth_v4l2`: live RGB-D cameras (v4l2_depth_source.h) into the RGB-D frame
// channel (`depth_images`, announced on `depth_frames`), as camera_depth_sim and
// camera_depth_replay publish it for depth_tracking. Parameters: cameras: DIR (cam0.yaml.. depth
// calibrations, depth_camera.h; fixed cameras only), depth_devices: [/dev/videoN, ...] (each
// camera's Z16 depth node), colour_devices: [...] (each camera's colour node, its image registered
// to the depth: same size and optics, as a D405's; outside /dev an image sequence pattern),
// wait_ms (how long a grab waits for a camera's depth image, 1..1000, default 100),
// reconnect_initial_s (default 0.5), reconnect_max_s (default 5), and camera_plugin.h's. A camera
// that does not open or stops is dark (status degraded) and reopened with a back-off; each
// reconnect is logged from the update (RT log, with the running count); the counts (reconnects,
// depth images missed, colour images of the wrong size) are printed at deactivate.
// Outputs: depth_frames (crease::CameraFrames).
#include <cstdio>

#include "plugins/cameras/camera_plugin.h"
#include "plugins/cameras/v4l2_depth_source.h"

namespace {

using namespace crease::vision;

class CameraDepthV4l2Plugin final : public CameraPlugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    auto cams = load_depth_camera_dir(p.get_path("cameras", "cameras"));
    for (std::size_t k = 0; k < cams.size(); ++k)
      if (cams[k].mount)
        p.fail("cameras", "cam" + std::to_string(k) +
                              ".yaml is a camera the robot carries (mount keys): its pose at each "
                              "capture is not read live yet");
    const auto depth = read_device_list(p, "depth_devices");
    const auto colour = read_device_list(p, "colour_devices");
    if (depth.size() != cams.size())
      p.fail("depth_devices", std::to_string(depth.size()) + " devices for " +
                                  std::to_string(cams.size()) + " calibrations");
    if (colour.size() != cams.size())
      p.fail("colour_devices", std::to_string(colour.size()) + " devices for " +
                                   std::to_string(cams.size()) + " calibrations");
    if (cams.size() > V4l2DepthSource::kMaxCameras)
      p.fail("cameras", std::to_string(cams.size()) + " cameras, at most " +
                            std::to_string(V4l2DepthSource::kMaxCameras));
    const ReconnectPolicy retry = read_reconnect_policy(p);
    const int wait_ms = p.get_in_range<int>("wait_ms", 100, 1, 1000);
    auto src = std::make_unique<V4l2DepthSource>(std::move(cams), depth, colour, retry, wait_ms);
    for (const std::string& why : src->failed())
      std::fprintf(
          stderr,
          "camera_depth_v4l2 %s: %s; that camera is dark until it opens (retried every %g..%g s)\n",
          instance_name().c_str(), why.c_str(), retry.initial_s, retry.max_s);
    source_ = src.get();  // owned by the worker, which lives until cleanup()
    configure_camera(p, ports, std::move(src), true, kDepthImagesPort, kDepthFramesPort);
  }

  crease::Status update(const crease::Cycle& cycle) override {
    const crease::Status s = CameraPlugin::update(cycle);
    log_reconnects_rt(
        source_->reconnects(),
        "depth camera reconnected; reconnects so far");  // an atomic the worker counts
    return s;
  }

  void deactivate() override {
    CameraPlugin::deactivate();
    std::fprintf(
        stderr,
        "camera_depth_v4l2 %s: %llu reconnects, %llu depth images missed, %llu colour images of "
        "the wrong size\n",
        instance_name().c_str(), static_cast<unsigned long long>(source_->reconnects()),
        static_cast<unsigned long long>(source_->missed_depth()),
        static_cast<unsigned long long>(source_->wrong_colour()));
  }

 private:
  const V4l2DepthSource* source_ = nullptr;
};

}  // namespace

CREASE_PLUGIN(CameraDepthV4l2Plugin, "camera_depth_v4l2", "1.0.0")
