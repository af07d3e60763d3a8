// Reads a recorded directory in the replay layout (camera_source.h), frame by frame, as recorded:
//   DIR/camK.yaml            calibration of camera K
//   DIR/camK/NNNNNN.png      frame NNNNNN of camera K (8-bit grey); missing = nothing that frame
//   (a depth recording, its calibrations with depth_unit_mm: camK/NNNNNN.png 16-bit depth and
//   camK/NNNNNN.colour.png BGR; camera_source.h)
//   DIR/timestamps.csv       the header `frame,timestamp_ns`, then one line `INDEX,STAMP` per
//   frame:
//                            INDEX a non-negative integer greater than the line before's, STAMP
//                            integer nanoseconds (CLOCK_MONOTONIC of the recording machine), >= 0
//                            and not decreasing; nothing else on a line
//   (a carried camera, its calibration with the mount keys: DIR/camK/poses.csv, its pose per
//   frame, camera_source.h: the header exactly as written, then `INDEX,` and twelve numbers per
//   line, the frame indices increasing, each number finite and read back as printed; a frame
//   without a line is one it did not deliver. A recording without mount keys, any recording
//   made before poses were recorded, plays as fixed cameras.)
// Every departure from that (another header, a fraction or seconds, a sign, trailing text, a
// decreasing stamp, a repeated frame index) is a crease::ConfigError naming the file and line.
// Not RT (file I/O, PNG decoding, OpenCV allocation). Stateless after construction: read()
// may be called from one thread at a time for any frame, in any order.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/frames/frame_channel.h"
#include "plugins/camera_rig/camera_model.h"
#include "plugins/camera_rig/camera_mount.h"
#include "plugins/cameras/camera_source.h"

namespace crease::vision {

struct RecordedStamp {
  std::uint64_t frame = 0;      // the recording's frame index (its PNG file names)
  std::int64_t stamp_ns = 0;    // the recorded capture time
};

// Parses a timestamps.csv text; `file` names it in errors ("FILE: line N: reason").
[[nodiscard]] std::vector<RecordedStamp> parse_timestamps(const std::string& text, const std::string& file);

struct RecordedPose {
  std::uint64_t frame = 0;
  crease::frames::CameraPose pose;  // carried
};
// Parses a camK/poses.csv text; `file` names it in errors ("FILE: line N: reason").
[[nodiscard]] std::vector<RecordedPose> parse_poses(const std::string& text,
                                                    const std::string& file);

class ReplayReader {
 public:
  // Throws crease::ConfigError naming the file on a missing or bad calibration or timestamps.csv.
  explicit ReplayReader(const std::string& dir);
  [[nodiscard]] const std::vector<Camera>& cameras() const { return cameras_; }
  [[nodiscard]] const std::vector<RecordedStamp>& stamps() const { return stamps_; }
  [[nodiscard]] std::size_t frames() const { return stamps_.size(); }
  // A depth recording's unit per camera (mm per count); empty for grey cameras.
  [[nodiscard]] const std::vector<double>& depth_units_mm() const { return depth_units_mm_; }
  // Per camera of a depth recording, its mount (carried) or nullopt (fixed).
  [[nodiscard]] const std::vector<std::optional<CameraMount>>& mounts() const { return mounts_; }
  [[nodiscard]] bool any_carried() const { return any_carried_; }
  // Decodes recorded frame i (< frames()) into `frame`: fresh images, the recorded index and
  // stamp; with a carried camera, frame.poses (its recorded pose, the fixed cameras' `fixed`).
  // A missing or wrongly sized image is an empty one (that camera delivered nothing); so are a
  // carried camera's images of a frame without a recorded pose.
  void read(std::size_t i, Frame& frame) const;

 private:
  std::string dir_;
  std::vector<Camera> cameras_;
  std::vector<RecordedStamp> stamps_;
  std::vector<double> depth_units_mm_;
  std::vector<std::optional<CameraMount>> mounts_;
  bool any_carried_ = false;
  // Per camera, per recorded frame (stamps_' order): its pose; carried false when none recorded.
  std::vector<std::vector<crease::frames::CameraPose>> poses_;
};

}  // namespace crease::vision
