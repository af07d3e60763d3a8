// Offline scoring of a recorded tracked sheet against a recorded truth: both files as
// StateRecorder writes them (one JSON object per line, state_recorder.h). Each model frame is
// paired with the truth at the same time (stamp_ns when both files carry it, else t; plus a
// shift), the truth linear between the two recorded frames around it; model frames before the
// first or after the last truth frame are not scored (counted). Not RT: for crease-score.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace crease::sheet_score {

struct RecordedSheet {
  double t_s = 0;
  std::int64_t stamp_ns = 0;
  bool has_stamp = false;
  std::uint64_t frame = 0;
  int nodes_u = 0, nodes_v = 0;
  std::vector<std::array<double, 3>> nodes;  // world mm, row by row
};

// Reads a recording. Throws crease::Error "PATH:LINE: reason" for a line that is not such an
// object (bad JSON, a missing or mistyped field, a node count other than W x H, a time that
// goes back); an empty file is an error too.
[[nodiscard]] std::vector<RecordedSheet> read_recording(const std::string& path);

enum class Pairing { stamp, time };  // stamp_ns (one run's clock) or t (each recorder's start)

struct FrameScore {
  double t_s = 0;    // the model frame's t
  double err_mm = 0; // mean node distance from the truth at that time
};

struct RecordingScore {
  std::vector<FrameScore> frames;
  int skipped = 0;  // model frames outside the truth's time span
  double mean_mm = 0, worst_mm = 0, worst_t_s = 0, end_mm = 0;
};

// The pairing both recordings allow: stamp when every line of both has stamp_ns.
[[nodiscard]] Pairing default_pairing(const std::vector<RecordedSheet>& model, const std::vector<RecordedSheet>& truth);

// Scores model against truth at time(model frame) + shift_s. Throws crease::Error when the
// grids differ or no frame could be scored.
[[nodiscard]] RecordingScore score_recording(const std::vector<RecordedSheet>& model,
                                             const std::vector<RecordedSheet>& truth, Pairing pairing,
                                             double shift_s = 0.0);

}  // namespace crease::sheet_score
