#include "plugins/camera_rig/depth_camera.h"

#include <cmath>
#include <filesystem>

#include <opencv2/core/persistence.hpp>

#include "core/assert.h"
#include "core/errors.h"

namespace crease::vision {

DepthCamera load_depth_camera(const std::string& path) {
  DepthCamera d;
  d.camera = load_camera(path);  // the file opens and parses: its own errors name it
  cv::FileStorage fs(path, cv::FileStorage::READ);
  const cv::FileNode n = fs["depth_unit_mm"];
  if (n.empty()) throw crease::ConfigError(path + ": key 'depth_unit_mm': missing");
  if (!n.isReal() && !n.isInt()) throw crease::ConfigError(path + ": key 'depth_unit_mm': expected a number");
  d.depth_unit_mm = static_cast<double>(n);
  if (!(d.depth_unit_mm > 0.0 && d.depth_unit_mm <= 10.0))
    throw crease::ConfigError(path + ": key 'depth_unit_mm': must be in (0, 10]");
  d.mount = load_camera_mount(path);
  return d;
}

void save_depth_camera(const DepthCamera& cam, const std::string& path) {
  save_camera(cam.camera, path);
  cv::FileStorage fs(path, cv::FileStorage::APPEND);
  if (!fs.isOpened()) throw crease::Error(path + ": cannot open for writing");
  fs << "depth_unit_mm" << cam.depth_unit_mm;
  fs.release();
  if (cam.mount) save_camera_mount(*cam.mount, path);
}

std::vector<DepthCamera> load_depth_camera_dir(const std::string& dir) {
  std::vector<DepthCamera> cams;
  for (int k = 0;; ++k) {
    const std::string p = dir + "/cam" + std::to_string(k) + ".yaml";
    if (!std::filesystem::exists(p)) break;
    cams.push_back(load_depth_camera(p));
  }
  crease::require_input(!cams.empty(), dir + ": no depth camera files cam0.yaml, cam1.yaml, ...");
  return cams;
}

std::vector<Camera> cameras_of(const std::vector<DepthCamera>& cams) {
  std::vector<Camera> out;
  for (const DepthCamera& c : cams) out.push_back(c.camera);
  return out;
}

std::vector<crease::frames::CameraSpec> depth_channel_specs(const std::vector<Camera>& cameras) {
  std::vector<crease::frames::CameraSpec> specs;
  for (const Camera& c : cameras) {
    specs.push_back({c.name + ".depth", c.width, c.height, 2});
    specs.push_back({c.name + ".colour", c.width, c.height, 3});
  }
  return specs;
}

std::shared_ptr<crease::frames::FrameChannel> bind_depth_images(crease::PortBinder& ports,
                                                                const std::vector<Camera>& cameras,
                                                                ImagesEnd end) {
  crease::require_input(2 * cameras.size() <= crease::frames::FrameChannel::kMaxCameras,
                        "depth cameras: at most " +
                            std::to_string(crease::frames::FrameChannel::kMaxCameras / 2));
  return bind_image_specs(ports, kDepthImagesPort, depth_channel_specs(cameras), end);
}

}  // namespace crease::vision
