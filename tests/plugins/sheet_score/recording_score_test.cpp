// Offline scoring of recordings: a model 2 mm above a moving truth scores 2 mm whether the two
// were recorded at different rates (the truth linear between its frames), paired by stamp or by
// t with a shift; frames outside the truth's span are counted, not scored; bad lines name the
// file and line.
#include "plugins/sheet_score/recording_score.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.h"

using namespace crease::sheet_score;

namespace {

// A 3 x 2 sheet whose nodes all sit at (x(t), 0, z): x = 10 mm/s * t.
void write_line(std::ofstream& out, double t, std::int64_t stamp_ns, int frame, double z, bool stamp = true) {
  out << "{\"t\":" << t;
  if (stamp) out << ",\"stamp_ns\":" << stamp_ns;
  out << ",\"frame\":" << frame << ",\"grid\":[3,2],\"size_mm\":[20,10],\"nodes\":[";
  for (int k = 0; k < 6; ++k) out << (k ? "," : "") << "[" << 10.0 * double(stamp_ns) * 1e-9 << ",0," << z << "]";
  out << "]}\n";
}

std::string temp(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("crease-score-" + std::to_string(::getpid()) + "-" + name)).string();
}

}  // namespace

TEST_CASE("a recorded model 2 mm above a recorded moving truth scores 2 mm") {
  const std::string model = temp("model.jsonl"), truth = temp("truth.jsonl");
  {
    std::ofstream m(model), t(truth);
    // The model at 60 Hz from 1.0 s to 2.0 s of the run's clock; the truth at 25 Hz from 0.5 s
    // to 1.78 s, its recorder started 0.3 s before the model's (its t is 0.3 s ahead).
    for (int f = 0; f <= 60; ++f) {
      const std::int64_t ns = 1'000'000'000 + f * 16'666'667;
      write_line(m, double(ns) * 1e-9 - 0.5, ns, f, 2.0);
    }
    for (int f = 0; f <= 32; ++f) {
      const std::int64_t ns = 500'000'000 + f * 40'000'000;
      write_line(t, double(ns) * 1e-9 - 0.2, ns, f, 0.0);
    }
  }
  const auto m = read_recording(model), t = read_recording(truth);
  REQUIRE(m.size() == 61);
  REQUIRE(t.size() == 33);
  CHECK(default_pairing(m, t) == Pairing::stamp);
  const RecordingScore by_stamp = score_recording(m, t, Pairing::stamp);
  CHECK(by_stamp.mean_mm == doctest::Approx(2.0).epsilon(1e-6));
  CHECK(by_stamp.end_mm == doctest::Approx(2.0).epsilon(1e-6));
  CHECK(by_stamp.skipped == 14);  // the model frames after the truth's last, 1.78 s
  CHECK(by_stamp.frames.size() == 47);
  // By t, the truth read 0.3 s later than the model's t: the same pairing.
  const RecordingScore by_time = score_recording(m, t, Pairing::time, 0.3);
  CHECK(by_time.mean_mm == doctest::Approx(2.0).epsilon(1e-4));
  // Misaligned by 0.1 s, the moving truth is 1 mm away along x: sqrt(1 + 4) mm.
  const RecordingScore late = score_recording(m, t, Pairing::stamp, 0.1);
  CHECK(late.mean_mm == doctest::Approx(std::sqrt(5.0)).epsilon(1e-4));
  std::filesystem::remove(model);
  std::filesystem::remove(truth);
}

TEST_CASE("recordings: a line without stamp pairs by time; bad lines name the file and line") {
  const std::string path = temp("bad.jsonl");
  auto expect_error = [&](const std::string& second_line, const std::string& says) {
    {
      std::ofstream out(path);
      write_line(out, 0.0, 0, 0, 0.0);
      out << second_line << "\n";
    }
    try {
      (void)read_recording(path);
      FAIL("accepted: " << second_line);
    } catch (const crease::Error& e) {
      const std::string what = e.what();
      CHECK(what.find(path + ":2: ") != std::string::npos);
      CHECK(what.find(says) != std::string::npos);
    }
  };
  expect_error("{\"t\":1,", "not JSON");
  expect_error("[1, 2]", "not a JSON object");
  expect_error("{\"t\":1,\"frame\":1,\"grid\":[3,2],\"nodes\":[[0,0,0]]}", "W x H");
  expect_error("{\"t\":\"one\",\"frame\":1,\"grid\":[3,2],\"nodes\":[]}", "mistyped");
  expect_error("{\"t\":-1,\"frame\":1,\"grid\":[1,1],\"nodes\":[[0,0,0]]}", "time goes back");
  {
    std::ofstream out(path);
    write_line(out, 0.0, 0, 0, 0.0, false);
  }
  const auto r = read_recording(path);
  CHECK(default_pairing(r, r) == Pairing::time);
  CHECK(score_recording(r, r, Pairing::time).mean_mm == 0.0);
  {
    std::ofstream out(path);
  }
  CHECK_THROWS_AS((void)read_recording(path), crease::Error);
  std::filesystem::remove(path);
}
