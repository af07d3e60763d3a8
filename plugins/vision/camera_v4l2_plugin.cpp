// Plugin `camera_v4l2`: live cameras through cv::VideoCapture into the frame channel.
// Parameters: cameras: DIR (cam0.yaml.. calibrations), devices: [/dev/video0, ...] (one per
// calibration; a path outside /dev, e.g. a video file or an image sequence pattern, opens with
// any OpenCV backend), and camera_plugin.h's. A device that does not open or stops delivering
// leaves the others working (status degraded); it is logged at configure time.
// Outputs: frames (crease::CameraFrames).
#include <cstdio>

#include "camera_plugin.h"

namespace {

using namespace crease::vision;

class CameraV4l2Plugin final : public CameraPlugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    auto cams = load_camera_dir(path_param(p, p.get<std::string>("cameras", "cameras")));
    std::vector<std::string> devices;
    const YAML::Node d = p.raw("devices");
    if (!d || !d.IsSequence()) p.fail("devices", "expected a list of video devices");
    for (const auto& n : d) devices.push_back(path_param(p, n.as<std::string>()));
    if (devices.size() != cams.size())
      p.fail("devices", std::to_string(devices.size()) + " devices for " +
                            std::to_string(cams.size()) + " calibrations");
    auto src = std::make_unique<V4l2Source>(std::move(cams), devices);
    for (const std::string& dev : src->failed_devices())
      std::fprintf(stderr, "camera_v4l2 %s: %s does not open; that camera delivers nothing\n",
                   instance_name().c_str(), dev.c_str());
    configure_camera(p, ports, std::move(src));
  }
};

}  // namespace

CREASE_PLUGIN(CameraV4l2Plugin, "camera_v4l2", "1.0.0")
