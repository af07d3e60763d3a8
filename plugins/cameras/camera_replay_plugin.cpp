// Plugin `camera_replay`: plays a recorded directory (camera_source.h, replay layout) into the
// frame channel, one frame per cycle; in lockstep with its reader (the default), so the same
// recording gives the same key-points every time.
// Parameters: replay_dir: DIR (its camK.yaml are the cameras), and camera_plugin.h's.
// Outputs: frames (crease::CameraFrames). Degraded when a camera's files stop and at the end.
#include "plugins/cameras/camera_plugin.h"

namespace {

class CameraReplayPlugin final : public crease::vision::CameraPlugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    auto src = std::make_unique<crease::vision::ReplaySource>(p.get_path("replay_dir"));
    configure_camera(p, ports, std::move(src));
  }
};

}  // namespace

CREASE_PLUGIN(CameraReplayPlugin, "camera_replay", "1.0.0")
