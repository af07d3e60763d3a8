#include "plugins/cameras/replay_reader.h"

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/assert.h"
#include "plugins/camera_rig/depth_camera.h"

namespace crease::vision {

namespace {

// A non-negative decimal integer filling [begin, end) exactly; false on anything else.
bool parse_uint(const std::string& s, std::size_t begin, std::size_t end, std::uint64_t& out) {
  if (begin >= end) return false;
  std::uint64_t v = 0;
  for (std::size_t i = begin; i < end; ++i) {
    const char c = s[i];
    if (c < '0' || c > '9') return false;
    const auto d = static_cast<std::uint64_t>(c - '0');
    if (v > (std::numeric_limits<std::uint64_t>::max() - d) / 10) return false;
    v = v * 10 + d;
  }
  out = v;
  return true;
}

// Calls ROW(line, fail) for each non-empty line after the header of the CSV file FILE (its
// TEXT), whose first line must be HEADER exactly (NOTE: what the reader adds to the message);
// FAIL(why) throws a ConfigError naming the file and the line.
template <class Row>
void for_each_row(const std::string& text, const std::string& file, const std::string& header,
                  const char* note, Row&& row) {
  std::istringstream in(text);
  std::string line;
  int lineno = 0;
  auto fail = [&](const std::string& why) {
    throw crease::ConfigError(file + ": line " + std::to_string(lineno) + ": " + why);
  };
  while (std::getline(in, line)) {
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();  // a file written on Windows
    if (lineno == 1) {
      if (line != header)
        fail("the header must be exactly '" + header + "'" + note + ", not '" + line + "'");
      continue;
    }
    if (!line.empty()) row(line, fail);
  }
  if (lineno == 0) {
    lineno = 1;
    fail("empty file: expected the header '" + header + "'");
  }
}

}  // namespace

std::vector<RecordedStamp> parse_timestamps(const std::string& text, const std::string& file) {
  std::vector<RecordedStamp> out;
  for_each_row(
      text, file, "frame,timestamp_ns", " (integer nanoseconds)",
      [&](const std::string& line, auto& fail) {
        const std::size_t comma = line.find(',');
        std::uint64_t frame = 0, stamp = 0;
        if (comma == std::string::npos || !parse_uint(line, 0, comma, frame))
          fail("expected 'FRAME,TIMESTAMP_NS' with a non-negative integer frame index, not '" +
               line + "'");
        if (!parse_uint(line, comma + 1, line.size(), stamp) ||
            stamp > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
          fail(
              "the timestamp must be a non-negative integer of nanoseconds with nothing after it, "
              "not '" +
              line.substr(comma + 1) + "'");
        const auto t = static_cast<std::int64_t>(stamp);
        if (!out.empty() && frame <= out.back().frame)
          fail("frame " + std::to_string(frame) + " after frame " +
               std::to_string(out.back().frame) + ": frame indices must increase");
        if (!out.empty() && t < out.back().stamp_ns)
          fail("timestamp " + std::to_string(t) + " ns before the previous frame's " +
               std::to_string(out.back().stamp_ns) + " ns: stamps must not decrease");
        out.push_back({frame, t});
      });
  return out;
}

std::vector<RecordedPose> parse_poses(const std::string& text, const std::string& file) {
  std::vector<RecordedPose> out;
  for_each_row(text, file, kReplayPosesHeader, "", [&](const std::string& line, auto& fail) {
    RecordedPose r;
    r.pose.carried = true;
    std::size_t comma = line.find(',');
    if (comma == std::string::npos || !parse_uint(line, 0, comma, r.frame))
      fail("expected 'FRAME,' and twelve numbers with a non-negative integer frame index, not '" +
           line + "'");
    for (int k = 0; k < 12; ++k) {
      const std::size_t begin = comma + 1;
      comma = line.find(',', begin);
      const std::size_t end = comma == std::string::npos ? line.size() : comma;
      if ((k < 11) != (comma != std::string::npos))
        fail(
            "expected twelve numbers after the frame index (rotation row by row, x_mm, y_mm, "
            "z_mm), not '" +
            line + "'");
      const std::string field = line.substr(begin, end - begin);
      char* stop = nullptr;
      const double v = field.empty() ? 0.0 : std::strtod(field.c_str(), &stop);
      if (field.empty() || stop != field.c_str() + field.size() || !std::isfinite(v))
        fail("number " + std::to_string(k + 1) + " '" + field + "' is not a finite number");
      (k < 9 ? r.pose.rotation[k] : r.pose.translation_mm[k - 9]) = v;
    }
    if (!out.empty() && r.frame <= out.back().frame)
      fail("frame " + std::to_string(r.frame) + " after frame " + std::to_string(out.back().frame) +
           ": frame indices must increase");
    out.push_back(r);
  });
  return out;
}

ReplayReader::ReplayReader(const std::string& dir) : dir_(dir) {
  // A depth recording's calibrations carry depth_unit_mm (camera_source.h's layout).
  bool depth = false;
  {
    cv::FileStorage fs;
    try {
      fs.open(dir + "/cam0.yaml", cv::FileStorage::READ);
    } catch (const cv::Exception&) {
    }
    depth = fs.isOpened() && !fs["depth_unit_mm"].empty();
  }
  if (depth) {
    const std::vector<DepthCamera> cams = load_depth_camera_dir(dir);
    cameras_ = cameras_of(cams);
    for (const DepthCamera& c : cams) {
      depth_units_mm_.push_back(c.depth_unit_mm);
      mounts_.push_back(c.mount);
      any_carried_ = any_carried_ || c.mount.has_value();
    }
  } else {
    cameras_ = load_camera_dir(dir);
  }
  const std::string csv = dir + "/timestamps.csv";
  std::ifstream in(csv);
  crease::require_input(static_cast<bool>(in), csv + ": cannot read");
  std::ostringstream text;
  text << in.rdbuf();
  stamps_ = parse_timestamps(text.str(), csv);
  // Carried cameras: their pose per recorded frame, by frame index (a pose of a frame not in
  // timestamps.csv is never played).
  poses_.assign(cameras_.size(), {});
  for (std::size_t k = 0; k < mounts_.size(); ++k) {
    if (!mounts_[k]) continue;
    const std::string file = replay_poses_path(dir, k);
    std::ifstream pin(file);
    crease::require_input(static_cast<bool>(pin), file + ": cannot read (cam" + std::to_string(k) +
                                                      ".yaml names a mount: a carried camera's "
                                                      "recording has its pose per frame)");
    std::ostringstream ptext;
    ptext << pin.rdbuf();
    const std::vector<RecordedPose> recorded = parse_poses(ptext.str(), file);
    auto& per_frame = poses_[k];
    per_frame.assign(stamps_.size(), crease::frames::CameraPose{});
    std::size_t j = 0;
    for (std::size_t i = 0; i < stamps_.size(); ++i) {
      while (j < recorded.size() && recorded[j].frame < stamps_[i].frame) ++j;
      if (j < recorded.size() && recorded[j].frame == stamps_[i].frame)
        per_frame[i] = recorded[j].pose;
    }
  }
}

void ReplayReader::read(std::size_t i, Frame& frame) const {
  CREASE_DEMAND(i < stamps_.size(), "ReplayReader::read past the recording's end");
  const RecordedStamp& s = stamps_[i];
  frame.index = s.frame;
  frame.timestamp_ns = s.stamp_ns;
  const bool depth = !depth_units_mm_.empty();
  const std::size_t per = depth ? 2 : 1;  // depth: camera k's depth at 2k, its colour at 2k + 1
  frame.images.resize(per * cameras_.size());
  frame.poses.clear();
  if (any_carried_) {
    frame.poses.assign(per * cameras_.size(), crease::frames::CameraPose{});
    for (std::size_t k = 0; k < cameras_.size(); ++k)
      if (mounts_[k]) frame.poses[2 * k] = frame.poses[2 * k + 1] = poses_[k][i];
  }
  const auto load = [](const std::string& p, int flags, int type, const Camera& c) {
    cv::Mat m = std::filesystem::exists(p) ? cv::imread(p, flags) : cv::Mat();
    if (!m.empty() && (m.cols != c.width || m.rows != c.height || m.type() != type)) m = cv::Mat();
    return m;  // missing, or not this camera's kind or size of image: nothing delivered
  };
  for (std::size_t k = 0; k < cameras_.size(); ++k) {
    const Camera& c = cameras_[k];
    if (!depth) {
      frame.images[k] = load(replay_frame_path(dir_, k, s.frame), cv::IMREAD_GRAYSCALE, CV_8UC1, c);
      continue;
    }
    if (mounts_[k] && !poses_[k][i].carried) {  // a carried camera with no pose: nothing
      frame.images[2 * k] = cv::Mat();
      frame.images[2 * k + 1] = cv::Mat();
      continue;
    }
    frame.images[2 * k] =
        load(replay_frame_path(dir_, k, s.frame), cv::IMREAD_UNCHANGED, CV_16UC1, c);
    frame.images[2 * k + 1] =
        load(replay_colour_path(dir_, k, s.frame), cv::IMREAD_COLOR, CV_8UC3, c);
  }
}

}  // namespace crease::vision
