// The replay layout's timestamps.csv is read exactly as the recorder writes it: the header
// `frame,timestamp_ns`, then `INDEX,STAMP` lines of integers, frame indices increasing, stamps
// not decreasing. Anything else is a crease::ConfigError naming the file and the line, never a
// stamp quietly read as something else (seconds `0.066667` read as 0 made every stamp 0).
// A depth recording (16-bit depth and colour PNGs) reads back as the recorder wrote it; a carried
// camera's pose per frame (camK/poses.csv) too, bit for bit, and a bad poses.csv names its line.
#include "plugins/cameras/replay_reader.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "core/errors.h"

using namespace crease::vision;

namespace {
// The error parse_timestamps gives for `text`, or "" when it parsed.
std::string error_of(const std::string& text) {
  try {
    (void)parse_timestamps(text, "rec/timestamps.csv");
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_CASE("timestamps.csv as the recorder writes it") {
  const auto s = parse_timestamps("frame,timestamp_ns\n0,100\n1,200\n3,200\n\n7,9223372036854775807\n", "t.csv");
  REQUIRE(s.size() == 4);
  CHECK(s[0].frame == 0);
  CHECK(s[0].stamp_ns == 100);
  CHECK(s[2].frame == 3);  // a frame the recorder skipped: indices need only increase
  CHECK(s[2].stamp_ns == 200);  // equal stamps are allowed
  CHECK(s[3].stamp_ns == 9223372036854775807LL);
  CHECK(parse_timestamps("frame,timestamp_ns\r\n0,5\r\n", "t.csv").size() == 1);  // CRLF lines
  CHECK(parse_timestamps("frame,timestamp_ns\n", "t.csv").empty());
}

TEST_CASE("every other timestamps.csv is an error naming the file and the line") {
  struct Case {
    const char* text;
    int line;
    const char* says;
  };
  const Case cases[] = {
      {"frame,t\n0,0.066667\n", 1, "header must be exactly 'frame,timestamp_ns'"},  // seconds
      {"frame,timestamp_ns\n0,0.066667\n", 2, "non-negative integer of nanoseconds"},  // a fraction
      {"frame,timestamp_ns\n0,66e6\n", 2, "non-negative integer of nanoseconds"},
      {"frame,timestamp_ns\n0,-5\n", 2, "non-negative integer of nanoseconds"},  // negative
      {"frame,timestamp_ns\n0,+5\n", 2, "non-negative integer of nanoseconds"},
      {"frame,timestamp_ns\n0,100\n1,99\n", 3, "stamps must not decrease"},
      {"frame,timestamp_ns\n0,100\n0,200\n", 3, "frame indices must increase"},  // repeated
      {"frame,timestamp_ns\n4,100\n2,200\n", 3, "frame indices must increase"},
      {"frame,timestamp_ns\n0,100 \n", 2, "nothing after it"},  // trailing text
      {"frame,timestamp_ns\n0,100,cam0\n", 2, "nothing after it"},
      {"frame,timestamp_ns\n0,100 # first\n", 2, "nothing after it"},
      {"frame,timestamp_ns\n0;12\n", 2, "expected 'FRAME,TIMESTAMP_NS'"},
      {"frame,timestamp_ns\n-1,12\n", 2, "expected 'FRAME,TIMESTAMP_NS'"},
      {"frame,timestamp_ns\n,12\n", 2, "expected 'FRAME,TIMESTAMP_NS'"},
      {"frame,timestamp_ns\n0,\n", 2, "non-negative integer of nanoseconds"},
      {"frame,timestamp_ns\n0,99999999999999999999\n", 2, "non-negative integer of nanoseconds"},
      {"frame,timestamp_ns,exposure\n0,1,2\n", 1, "header must be exactly"},
      {"0,100\n1,200\n", 1, "header must be exactly"},  // no header
      {"", 1, "empty file"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.text);
    const std::string what = error_of(c.text);
    CAPTURE(what);
    CHECK(what.find("rec/timestamps.csv: line " + std::to_string(c.line) + ": ") == 0);
    CHECK(what.find(c.says) != std::string::npos);
  }
}

TEST_CASE("a recorded directory with a bad timestamps.csv does not open; the reader reads frames as recorded") {
  const auto dir = std::filesystem::temp_directory_path() / ("crease_replay_reader_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "cam0");
  save_camera(look_at_camera("a", 64, 48, 60, {0, -60, 450}, {0, 0, 0}), (dir / "cam0.yaml").string());
  REQUIRE(cv::imwrite((dir / "cam0" / "000003.png").string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(90))));
  std::ofstream(dir / "timestamps.csv") << "frame,t\n0,0.066667\n";
  const std::string where = (dir / "timestamps.csv").string() + ": line 1: ";
  CHECK_THROWS_WITH_AS(ReplayReader{dir.string()}, doctest::Contains(where.c_str()), crease::ConfigError);
  std::ofstream(dir / "timestamps.csv") << "frame,timestamp_ns\n3,5000\n4,6000\n";
  const ReplayReader r(dir.string());
  REQUIRE(r.frames() == 2);
  Frame f;
  r.read(0, f);
  CHECK(f.index == 3);
  CHECK(f.timestamp_ns == 5000);  // the reader keeps the recorded time; ReplaySource re-bases it
  REQUIRE(f.images.size() == 1);
  CHECK(f.images[0].at<unsigned char>(10, 10) == 90);
  r.read(1, f);
  CHECK(f.images[0].empty());  // no file for frame 4: that camera delivered nothing
  std::filesystem::remove_all(dir);
}

TEST_CASE(
    "a depth recording as the recorder writes it reads back bit for bit: 16-bit depth, colour, "
    "units") {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("crease_depth_replay_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::vector<Camera> cams = {look_at_camera("a", 64, 48, 60, {0, -60, 450}, {0, 0, 0}),
                                    look_at_camera("b", 64, 48, 60, {0, 60, 450}, {0, 0, 0})};
  cv::RNG rng(3);
  std::vector<Frame> written(3);
  {
    Recorder rec(dir.string(), cams, {1.0, 0.1});
    for (std::size_t i = 0; i < written.size(); ++i) {
      Frame& f = written[i];
      f.index = i;
      f.timestamp_ns = 1'000'000 + static_cast<std::int64_t>(i) * 33'333'333;
      for (std::size_t k = 0; k < cams.size(); ++k) {
        cv::Mat depth(48, 64, CV_16UC1), colour(48, 64, CV_8UC3);
        rng.fill(depth, cv::RNG::UNIFORM, 0, 65536);
        rng.fill(colour, cv::RNG::UNIFORM, 0, 256);
        f.images.push_back(depth);
        f.images.push_back(colour);
      }
    }
    written[2].images[3] = cv::Mat();  // camera b's colour missing in the last frame
    for (const Frame& f : written) rec.write(f);
  }
  const ReplayReader r(dir.string());
  REQUIRE(r.frames() == written.size());
  CHECK(r.depth_units_mm() == std::vector<double>{1.0, 0.1});
  CHECK_FALSE(r.any_carried());  // no mount keys, no poses.csv: fixed cameras, as before poses
  REQUIRE(r.cameras().size() == 2);
  CHECK(r.cameras()[1].width == 64);
  CHECK(r.cameras()[1].height == 48);
  for (std::size_t i = 0; i < written.size(); ++i) {
    CAPTURE(i);
    Frame f;
    r.read(i, f);
    CHECK(f.index == i);
    CHECK(f.timestamp_ns == written[i].timestamp_ns);
    CHECK(f.poses.empty());  // every camera fixed: its calibration says where
    REQUIRE(f.images.size() == 4);
    for (std::size_t m = 0; m < 4; ++m) {
      CAPTURE(m);
      const cv::Mat& want = written[i].images[m];
      REQUIRE(f.images[m].empty() == want.empty());
      if (want.empty()) continue;
      CHECK(f.images[m].type() == want.type());
      CHECK(cv::norm(f.images[m], want, cv::NORM_INF) == 0);
    }
  }
  // A depth image of another camera's size, or an 8-bit one where 16 bits belong: nothing
  // delivered, never a wrong image.
  REQUIRE(
      cv::imwrite(replay_frame_path(dir.string(), 0, 0), cv::Mat(48, 64, CV_8UC1, cv::Scalar(7))));
  REQUIRE(
      cv::imwrite(replay_frame_path(dir.string(), 1, 0), cv::Mat(40, 64, CV_16UC1, cv::Scalar(7))));
  Frame f;
  r.read(0, f);
  CHECK(f.images[0].empty());
  CHECK(f.images[2].empty());
  CHECK_FALSE(f.images[1].empty());
  std::filesystem::remove_all(dir);
}

namespace {
std::string poses_error_of(const std::string& text) {
  try {
    (void)parse_poses(text, "rec/cam1/poses.csv");
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  return "";
}

bool same_bits(const crease::frames::CameraPose& a, const crease::frames::CameraPose& b) {
  return a.carried == b.carried && std::memcmp(a.rotation, b.rotation, sizeof a.rotation) == 0 &&
         std::memcmp(a.translation_mm, b.translation_mm, sizeof a.translation_mm) == 0;
}
}  // namespace

TEST_CASE(
    "a carried camera's recording reads back its pose per frame bit for bit; the fixed one none") {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("crease_carried_replay_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::vector<Camera> cams = {look_at_camera("a", 64, 48, 60, {0, -60, 450}, {0, 0, 0}),
                                    look_at_camera("b", 64, 48, 60, {0, 60, 450}, {0, 0, 0})};
  const CameraMount wrist{0, crease::WorldShapes::Role::hand, 1};
  cv::RNG rng(5);
  std::vector<Frame> written(4);
  {
    Recorder rec(dir.string(), cams, {1.0, 0.1}, {std::nullopt, wrist});
    for (std::size_t i = 0; i < written.size(); ++i) {
      Frame& f = written[i];
      f.index = 2 * i;  // indices need only increase
      f.timestamp_ns = static_cast<std::int64_t>(i) * 33'333'333;
      for (std::size_t k = 0; k < cams.size(); ++k) {
        cv::Mat depth(48, 64, CV_16UC1), colour(48, 64, CV_8UC3);
        rng.fill(depth, cv::RNG::UNIFORM, 0, 65536);
        rng.fill(colour, cv::RNG::UNIFORM, 0, 256);
        f.images.push_back(depth);
        f.images.push_back(colour);
      }
      // Camera b where a turning arm put it: a rotation of full double precision, a centre with
      // digits no short decimal holds.
      cv::Matx33d R;
      cv::Rodrigues(
          cv::Vec3d(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)), R);
      const cv::Vec3d t(rng.uniform(-500.0, 500.0) / 3, 1.0 / 3 + static_cast<double>(i), -0.0);
      f.poses.assign(4, crease::frames::CameraPose{});
      f.poses[2] = f.poses[3] = carried_pose(R, t);
    }
    written[1].images[2] = written[1].images[3] = cv::Mat();  // b not posed then: no images
    written[1].poses[2] = written[1].poses[3] = crease::frames::CameraPose{};
    for (const Frame& f : written) rec.write(f);
  }
  const ReplayReader r(dir.string());
  REQUIRE(r.frames() == written.size());
  CHECK(r.any_carried());
  REQUIRE(r.mounts().size() == 2);
  CHECK_FALSE(r.mounts()[0].has_value());
  REQUIRE(r.mounts()[1].has_value());
  CHECK(describe(*r.mounts()[1]) == "right hand #1");
  int posed = 0;
  for (std::size_t i = 0; i < written.size(); ++i) {
    CAPTURE(i);
    Frame f;
    r.read(i, f);
    REQUIRE(f.poses.size() == 4);
    CHECK_FALSE(f.poses[0].carried);  // the fixed camera
    CHECK(same_bits(f.poses[2], written[i].poses[2]));
    CHECK(same_bits(f.poses[3], written[i].poses[3]));
    CHECK(f.images[2].empty() == written[i].images[2].empty());
    posed += f.poses[2].carried ? 1 : 0;
  }
  CHECK(posed == 3);
  // A pose line lost: that frame of camera b delivers nothing, never images without their pose.
  {
    std::ifstream in(replay_poses_path(dir.string(), 1));
    std::string header, first;
    std::getline(in, header);
    std::getline(in, first);
    std::ofstream(replay_poses_path(dir.string(), 1)) << header << "\n" << first << "\n";
  }
  const ReplayReader cut(dir.string());
  Frame f;
  cut.read(2, f);
  CHECK(f.images[2].empty());
  CHECK(f.images[3].empty());
  CHECK_FALSE(f.images[0].empty());
  CHECK_FALSE(f.poses[2].carried);
  // The calibration names a mount but the pose file is gone: the recording does not open.
  std::filesystem::remove(replay_poses_path(dir.string(), 1));
  try {
    const ReplayReader none(dir.string());
    FAIL("opened");
  } catch (const crease::ConfigError& e) {
    CHECK(std::string(e.what()).find(replay_poses_path(dir.string(), 1) + ": cannot read") !=
          std::string::npos);
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("every other poses.csv is an error naming the file and the line") {
  const std::string h = std::string(kReplayPosesHeader) + "\n";
  const std::string id = ",1,0,0,0,1,0,0,0,1";
  CHECK(poses_error_of(h + "0" + id + ",1,2,3\n3" + id + ",4,5,6\n").empty());
  CHECK(poses_error_of("frame,pose\n").find("rec/cam1/poses.csv: line 1: the header must be") == 0);
  CHECK(poses_error_of("").find("line 1: empty file") != std::string::npos);
  CHECK(poses_error_of(h + "0" + id + ",1,2\n").find("line 2: expected twelve numbers") !=
        std::string::npos);
  CHECK(poses_error_of(h + "0" + id + ",1,2,3,4\n").find("line 2: expected twelve numbers") !=
        std::string::npos);
  CHECK(
      poses_error_of(h + "0" + id + ",1,2,nan\n").find("line 2: number 12 'nan' is not a finite") !=
      std::string::npos);
  CHECK(poses_error_of(h + "0" + id + ",1,2,3mm\n").find("line 2: number 12 '3mm'") !=
        std::string::npos);
  CHECK(poses_error_of(h + "0" + id + ",1,,3\n").find("line 2: number 11 ''") != std::string::npos);
  CHECK(poses_error_of(h + "-1" + id + ",1,2,3\n").find("line 2: expected 'FRAME,'") !=
        std::string::npos);
  CHECK(poses_error_of(h + "4" + id + ",1,2,3\n4" + id + ",1,2,3\n")
            .find("line 3: frame 4 after frame 4: frame indices must increase") !=
        std::string::npos);
}
