// The main job end to end: creased runs config/sim.yaml (the simulated world with its devices
// and the drivers, the world's sheet as truth, five rendered cameras, detection, triangulation,
// the sheet model), prints the tracking error against the truth, and records every model frame
// and the truth as JSON lines (--record-state, --record-truth), which crease-score scores
// offline to the figure creased printed. The world's sheet lies on the table at the pose its seed drew (seed 1: 15 mm
// off and turned 14 deg from where the model starts), so the model must find it and hold it.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

TEST_CASE("config/sim.yaml tracks the world's sheet and records every model frame") {
  char tmpl[] = "/tmp/crease-main-XXXXXX";
  const fs::path dir = mkdtemp(tmpl);
  const fs::path record = dir / "state.jsonl", truth = dir / "truth.jsonl";
  const std::string cmd = std::string(CREASE_BIN_DIR) + "/creased --config " CREASE_SOURCE_DIR "/config/sim.yaml" +
                          " --plugin-dir " CREASE_PLUGIN_DIR " --socket " + (dir / "s.sock").string() +
                          " --report-dir " + (dir / "reports").string() + " --duration 12 --log-level warn" +
                          " --record-state " + record.string() + " --record-truth " + truth.string() + " 2>&1";
  FILE* f = popen(cmd.c_str(), "r");
  REQUIRE(f != nullptr);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof(buf), f) != nullptr) out += buf;
  const int rc = pclose(f);
  INFO(out);
  REQUIRE(WIFEXITED(rc));
  CHECK(WEXITSTATUS(rc) == 0);

  // Progress every second with the tracking error, then the summary.
  CHECK(out.find("[5 s]") != std::string::npos);
  CHECK(out.find("tracking error of sheet_state vs sheet_truth: ") != std::string::npos);
  CHECK(out.find("(this second)") != std::string::npos);
  std::smatch m;
  const std::string text = out;
  REQUIRE(std::regex_search(text, m, std::regex("tracking error of sheet_state vs sheet_truth: mean ([0-9.]+) mm over ([0-9]+)")));
  const double mean_mm = std::stod(m[1]);
  const int frames = std::stoi(m[2]);
  // A loose bound on a shared machine (the figure of record comes from the run's own line):
  // a model that lost the sheet is off by 50 mm and more; a loaded machine (slower vision,
  // fewer key-points per model frame) was seen at 11.5 mm.
  CHECK(mean_mm < 25.0);
  // And it found the sheet: a model that stayed where it started is off by the world's draw
  // (28.7 mm at the worst node for seed 1) to the end; the found sheet ends within 0.1 mm.
  REQUIRE(std::regex_search(text, m, std::regex("tracking error of sheet_state vs sheet_truth: mean [0-9.]+ mm over [0-9]+ model frames, last ([0-9.]+) mm")));
  CHECK(std::stod(m[1]) < 5.0);
  // 720 model frames in 12 s at 60 Hz; skipped periods of a loaded machine are counted, not
  // replayed: only a stalled model loop scores fewer than half.
  CHECK(frames > 360);
  CHECK(out.find("faults: 0") != std::string::npos);

  // The recording: one JSON object per model frame, 15x21 nodes in world mm, frames in order.
  std::ifstream in(record);
  std::string line;
  int lines = 0;
  std::uint64_t last_frame = 0;
  bool in_order = true, shaped = true;
  while (std::getline(in, line)) {
    const auto j = nlohmann::json::parse(line);
    shaped = shaped && j["grid"] == nlohmann::json::array({15, 21}) && j["nodes"].size() == 315 &&
             j["size_mm"][0] == 210.0 && j.contains("t");
    const auto frame = j["frame"].get<std::uint64_t>();
    in_order = in_order && (lines == 0 || frame > last_frame);
    last_frame = frame;
    ++lines;
  }
  CHECK(lines > 360);
  CHECK(shaped);
  CHECK(in_order);
  CHECK(fs::exists(dir / "reports" / "report.html"));

  // Scored offline from the two recordings, paired by stamp: the figure creased printed (which
  // took the newest truth at each model frame; offline the truth is linear between frames).
  FILE* s = popen((std::string(CREASE_BIN_DIR) + "/crease-score " + record.string() + " --truth " + truth.string() +
                   " 2>&1").c_str(), "r");
  REQUIRE(s != nullptr);
  std::string scored;
  while (std::fgets(buf, sizeof(buf), s) != nullptr) scored += buf;
  const int src = pclose(s);
  INFO(scored);
  REQUIRE(WIFEXITED(src));
  CHECK(WEXITSTATUS(src) == 0);
  REQUIRE(std::regex_search(scored, m, std::regex("score: frames=([0-9]+) skipped=[0-9]+ mean_mm=([0-9.]+)")));
  CHECK(std::stoi(m[1]) > frames - 10);
  CHECK(std::fabs(std::stod(m[2]) - mean_mm) < 0.05 * mean_mm + 0.2);
  fs::remove_all(dir);
}
