// Camera sources: N synchronised grey images per frame from a synthetic renderer, a recorded
// directory or live V4L2 devices, and a recorder writing the replay layout:
//   DIR/camK.yaml            calibration of camera K (camera_model.h format)
//   DIR/camK/NNNNNN.png      frame NNNNNN of camera K (8-bit grey)
//   DIR/timestamps.csv       "frame,timestamp_ns" header, one line per frame
// A camera that delivers nothing this frame leaves its image empty; the others go on.
// Not RT code (file and device I/O, OpenCV allocation): run it on a vision worker thread.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "camera_model.h"
#include "sheet_mesh.h"
#include "view_renderer.h"

namespace crease::vision {

struct Frame {
  std::int64_t timestamp_ns = 0;
  std::uint64_t index = 0;
  std::vector<cv::Mat> images;  // one per camera, CV_8UC1; empty = nothing from that camera
  // Set by the caller: images[k] are buffers of the right size to write into (a frame channel's
  // set); a source that can fill them in place does (SimSource), instead of fresh buffers.
  bool fill_in_place = false;
};

class CameraSource {
 public:
  virtual ~CameraSource() = default;
  [[nodiscard]] virtual const std::vector<Camera>& cameras() const = 0;
  // Fills the next frame; false at the end of a recording (or when no camera delivers).
  virtual bool grab(Frame& frame) = 0;
};

// Renders the mesh returned by `mesh_at(frame index)` for every camera; frame i is stamped
// start_ns + i * period_ns (pass the CLOCK_MONOTONIC start time in a running system).
class SimSource final : public CameraSource {
 public:
  SimSource(std::shared_ptr<const ViewRenderer> renderer, std::function<SheetMesh(std::uint64_t)> mesh_at,
            RenderOptions options, std::int64_t period_ns, std::int64_t start_ns = 0);
  [[nodiscard]] const std::vector<Camera>& cameras() const override { return renderer_->cameras(); }
  bool grab(Frame& frame) override;

 private:
  std::shared_ptr<const ViewRenderer> renderer_;
  std::function<SheetMesh(std::uint64_t)> mesh_at_;
  RenderOptions options_;
  std::int64_t period_ns_;
  std::int64_t start_ns_;
  std::uint64_t next_ = 0;
};

// Reads a recorded directory. Throws std::runtime_error naming the file on a missing or bad
// calibration or timestamps.csv; a missing image is an empty image (that camera stopped).
class ReplaySource final : public CameraSource {
 public:
  explicit ReplaySource(const std::string& dir);
  [[nodiscard]] const std::vector<Camera>& cameras() const override { return cameras_; }
  bool grab(Frame& frame) override;
  [[nodiscard]] std::size_t frames() const { return stamps_.size(); }

 private:
  std::string dir_;
  std::vector<Camera> cameras_;
  std::vector<std::pair<std::uint64_t, std::int64_t>> stamps_;  // frame index, timestamp
  std::size_t next_ = 0;
};

// Live cameras through cv::VideoCapture; device k is cameras[k]. /dev/... opens with the V4L2
// backend; any other string (a video file, an image sequence pattern) with whichever backend
// OpenCV finds. A device that does not open, stops, or delivers another image size gives empty
// images (the others go on); grab() never ends.
class V4l2Source final : public CameraSource {
 public:
  // Throws std::invalid_argument when devices and calibrations differ in number.
  V4l2Source(std::vector<Camera> cameras, const std::vector<std::string>& devices);
  [[nodiscard]] const std::vector<Camera>& cameras() const override { return cameras_; }
  bool grab(Frame& frame) override;
  // The devices that did not open.
  [[nodiscard]] const std::vector<std::string>& failed_devices() const { return failed_; }

 private:
  std::vector<Camera> cameras_;
  std::vector<cv::VideoCapture> caps_;
  std::vector<std::string> failed_;
  std::uint64_t next_ = 0;
};

// Writes frames in the replay layout (the `record` option of every source).
class Recorder {
 public:
  Recorder(const std::string& dir, const std::vector<Camera>& cameras);
  void write(const Frame& frame);

 private:
  std::string dir_;
  std::size_t ncam_;
  std::FILE* stamps_ = nullptr;

 public:
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;
};

}  // namespace crease::vision
