// crease-score: the tracking error of a recorded run, offline. Scores each model frame of a
// state recording (creased --record-state FILE, or sheet_score's `record`) against the truth
// recorded beside it (sheet_score's `record_truth`), paired by their states' stamps when both
// files carry them (one run's clock), else by their t, plus --shift-s; the truth linear
// between its recorded frames. Prints the frames scored, the mean, worst and last error;
// --per-frame prints "t err_mm" for every frame. Exit 0; 2 for bad input (FILE:LINE: reason).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>

#include "core/errors.h"
#include "plugins/sheet_score/recording_score.h"

int main(int argc, char** argv) {
  CLI::App app{"crease-score: a recorded tracked sheet against a recorded truth"};
  std::string state_file, truth_file, pairing = "auto";
  double shift_s = 0;
  bool per_frame = false;
  app.add_option("state", state_file, "the model's recording (JSON lines)")->required();
  app.add_option("--truth", truth_file, "the truth's recording (JSON lines)")->required();
  app.add_option("--pair-by", pairing, "stamp, time or auto (stamp when both files carry stamps)")
      ->check(CLI::IsMember({"auto", "stamp", "time"}));
  app.add_option("--shift-s", shift_s, "the truth is read at the model frame's time plus this");
  app.add_flag("--per-frame", per_frame, "print every frame's error");
  CLI11_PARSE(app, argc, argv);
  using namespace crease::sheet_score;
  try {
    const auto model = read_recording(state_file);
    const auto truth = read_recording(truth_file);
    Pairing p = default_pairing(model, truth);
    if (pairing == "time") p = Pairing::time;
    if (pairing == "stamp") {
      if (p != Pairing::stamp) throw crease::Error("--pair-by stamp: a recording has lines without stamp_ns");
      p = Pairing::stamp;
    }
    const RecordingScore r = score_recording(model, truth, p, shift_s);
    if (per_frame)
      for (const FrameScore& f : r.frames) std::printf("%.6f %.3f\n", f.t_s, f.err_mm);
    std::printf("paired by %s: %zu model frames scored, %d outside the truth's span\n",
                p == Pairing::stamp ? "stamp" : "time", r.frames.size(), r.skipped);
    std::printf("mean node error %.2f mm, worst %.2f mm (t %.3f s), last %.2f mm\n", r.mean_mm, r.worst_mm,
                r.worst_t_s, r.end_mm);
    std::printf("score: frames=%zu skipped=%d mean_mm=%.3f worst_mm=%.3f end_mm=%.3f\n", r.frames.size(), r.skipped,
                r.mean_mm, r.worst_mm, r.end_mm);
    return 0;
  } catch (const crease::Error& e) {
    std::fprintf(stderr, "crease-score: %s\n", e.what());
    return 2;
  }
}
