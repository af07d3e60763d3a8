// Plugin `camera_v4l2`: live cameras through cv::VideoCapture into the frame channel.
// Parameters: cameras: DIR (cam0.yaml.. calibrations), devices: [/dev/video0, ...] (one per
// calibration; outside /dev an image sequence pattern dir/%06d.png, read file by file, or a
// video file), reconnect_initial_s (default 0.5), reconnect_max_s (default 5), and
// camera_plugin.h's. A device that does not open or stops delivering leaves the others working
// (status degraded while any camera is dark); the capture worker reopens it with a back-off
// from reconnect_initial_s doubling to reconnect_max_s, and it rejoins the frame set when it
// delivers again (status ok once every camera does). Each reconnect is logged from the update
// (RT log, with the running count); the counts per device are printed at deactivate.
// Outputs: frames (crease::CameraFrames).
#include <cstdio>

#include "plugins/cameras/camera_plugin.h"

namespace {

using namespace crease::vision;

class CameraV4l2Plugin final : public CameraPlugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    auto cams = load_camera_dir(p.get_path("cameras", "cameras"));
    const std::vector<std::string> devices = read_device_list(p, "devices");
    if (devices.size() != cams.size())
      p.fail("devices", std::to_string(devices.size()) + " devices for " +
                            std::to_string(cams.size()) + " calibrations");
    const ReconnectPolicy retry = read_reconnect_policy(p);
    devices_ = devices;
    auto src = std::make_unique<V4l2Source>(std::move(cams), devices, retry);
    for (const std::string& dev : src->failed_devices())
      std::fprintf(stderr,
                   "camera_v4l2 %s: %s does not open; that camera is dark until it does "
                   "(retried every %g..%g s)\n",
                   instance_name().c_str(), dev.c_str(), retry.initial_s, retry.max_s);
    const V4l2Source* source = src.get();
    configure_camera(p, ports, std::move(src));
    source_ = source;  // owned by the worker, which lives until cleanup()
  }

  crease::Status update(const crease::Cycle& cycle) override {
    const crease::Status s = CameraPlugin::update(cycle);
    log_reconnects_rt(source_->reconnects(),
                      "camera reconnected; reconnects so far");  // an atomic the worker counts
    return s;
  }

  void deactivate() override {
    CameraPlugin::deactivate();
    for (std::size_t k = 0; k < devices_.size(); ++k)
      if (source_->reconnects(k) > 0)
        std::fprintf(stderr, "camera_v4l2 %s: %s reconnected %llu times\n",
                     instance_name().c_str(), devices_[k].c_str(),
                     static_cast<unsigned long long>(source_->reconnects(k)));
  }

 private:
  const V4l2Source* source_ = nullptr;
  std::vector<std::string> devices_;
};

}  // namespace

CREASE_PLUGIN(CameraV4l2Plugin, "camera_v4l2", "1.0.0")
