// The replay layout's timestamps.csv is read exactly as the recorder writes it: the header
// `frame,timestamp_ns`, then `INDEX,STAMP` lines of integers, frame indices increasing, stamps
// not decreasing. Anything else is a crease::ConfigError naming the file and the line, never a
// stamp quietly read as something else (seconds `0.066667` read as 0 made every stamp 0).
// A depth recording (16-bit depth and colour PNGs) reads back as the recorder wrote it.
#include "plugins/cameras/replay_reader.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
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
  REQUIRE(r.cameras().size() == 2);
  CHECK(r.cameras()[1].width == 64);
  CHECK(r.cameras()[1].height == 48);
  for (std::size_t i = 0; i < written.size(); ++i) {
    CAPTURE(i);
    Frame f;
    r.read(i, f);
    CHECK(f.index == i);
    CHECK(f.timestamp_ns == written[i].timestamp_ns);
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
