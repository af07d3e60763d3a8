// One folding trial of crease-trials: the simulated robot of a configuration (config/sim.yaml:
// the world with its devices, the drivers over the mocked buses, cameras, vision, the sheet
// model, the controllers and the folding sequence) run by creased's own body (core/daemon) in
// this process, the world drawn from the trial's seed. The sequence is started (as
// `creasectl sequence start` does), followed to done or aborted (an operator abort at the
// trial's time limit), and the trial scored from the world's truth (`sheet_truth`,
// `world_state`), never from the tracked model. Non-RT; one trial per process (the loops,
// buses and plugins are the process's).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/config/daemon_config.h"
#include "tools/trials/trial_score.h"

namespace crease::trials {

struct TrialOptions {
  std::string config;                    // the configuration file (sim.yaml)
  std::vector<std::string> plugin_dirs;  // empty: the configuration's
  std::string fold = "half";             // the sequence file folds/<fold>.yaml beside the configuration
  double max_fold_s = 300;               // from the sequence's start; then the operator's abort
  double ready_timeout_s = 60;           // the start waits for its guard at most this long
  double retain_s = 5;                   // after done (the hands released): then the retained angle
  std::string dir;                       // the trial's directory: its report, log, socket
  // --faults: the world's bus faults (plugins/sim_world/bus_faults.h) and camera dropouts
  // (camera_sim's `dropouts`), drawn from the trial's seed.
  bool faults = false;
  Bounds bounds;
};

// --faults: the trial's configuration with the faults on (every sim_world instance's `faults`,
// every camera_sim instance's `dropouts`, seeded by SEED). Throws when neither is present.
void enable_faults(config::DaemonConfig& cfg, std::uint64_t seed);

struct TimelineEntry {
  double t_s = 0;  // since the sequence's start
  std::string path, why;
};

// The trial over time, from the world's truth, every kSeriesS.
struct SeriesSample {
  double t_s = 0;              // since the sequence's start
  double force_n[2] = {0, 0};  // each hand's largest fingertip normal force (world_state) since the last sample
  double stretch = 0;          // the sheet's largest edge stretch (sheet_truth), NaN before one
  // Each hand's largest fingertip force as its force controller measured it (its tactile
  // sensors, hand_control_status) since the last sample, N; NaN without one. Beside force_n:
  // the sensors' estimate against the world's truth.
  double measured_n[2] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  // Which fingertip of each hand carried force_n (0 ff, 1 mf, 2 rf, 3 lf, 4 th; -1: none
  // pressed) and its height over the table then (mm): where a force limit comes from.
  int force_tip[2] = {-1, -1};
  double force_tip_z_mm[2] = {std::numeric_limits<double>::quiet_NaN(),
                              std::numeric_limits<double>::quiet_NaN()};
  // Each hand's contact detector (contact_state) at the sample: the fingers it has in contact
  // (bit f, 0: out of contact; -1: no state yet) and its onsets so far (a contact descent stops
  // on a new one).
  int contact_fingers[2] = {-1, -1};
  long contact_onsets[2] = {-1, -1};
  // How far the tracked sheet's frame (sheet_state's, in which the sequence's goals lie) puts
  // the near half's centre (u 105, v 74 mm, on the sheet) from where the truth's frame puts it,
  // mm; NaN without both. A contact descent 5 mm under the frame's plane misses a sheet lying
  // lower than that.
  double frame_err_mm = std::numeric_limits<double>::quiet_NaN();
  // ... and how far the truth's frame moved that point since the sequence's start (the world's
  // near half dragged, not the tracker wrong), mm.
  double frame_moved_mm = std::numeric_limits<double>::quiet_NaN();
  // The height over the table of the world's node at the fold's grasp point (grasp at_mm's u, v),
  // and the tracked sheet's, mm: a pinch that holds carries the first up through the bend;
  // lost, it lies on the table (pinch_lost judges the second).
  double grasp_z_mm = std::numeric_limits<double>::quiet_NaN();
  double grasp_tracked_z_mm = std::numeric_limits<double>::quiet_NaN();
  // Each hand's index pad (its tool frame in the fold) over the table at the sample, mm, in
  // contact or not: where a descent that touched nothing ended.
  double ff_z_mm[2] = {std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::quiet_NaN()};
  // Each hand's palm touching the sheet or the table (world; -1: no world state yet), and its
  // wrist's deflection from the commanded angles (the norm of WRJ2's and WRJ1's, deg): a hand
  // turned by something other than a fingertip (the palm, a finger's back) pressing.
  int palm_contact[2] = {-1, -1};
  double wrist_deflection_deg[2] = {std::numeric_limits<double>::quiet_NaN(),
                                    std::numeric_limits<double>::quiet_NaN()};
  // How far the tracked sheet puts the grasp point (above) from where the world's is (x, y, z),
  // mm: the tracker's error at the flap, which fold_lost and pinch_lost judge by; NaN without
  // both.
  double grasp_off_mm = std::numeric_limits<double>::quiet_NaN();
  // The tracked sheet's observations (sheet_state: the markers' key-points its last update took,
  // the targets not counted); -1 without a state.
  long observations = -1;
};
inline constexpr double kSeriesS = 0.02;

struct TrialResult {
  int index = 0;
  std::uint64_t seed = 0;
  std::string fold;
  std::string draws;         // what the seed drew (the world's randomisation)
  // How the sequence ended: done, aborted (by a fault, the reason below), time_limit (the
  // trial's operator abort), not_started (its start guard never passed), error.
  std::string end;
  std::string abort_reason;  // fold_sequence's reason name, "" when none
  std::string last_fold_state;  // the deepest state of the fold reached (before any abort)
  int fold_states = 0;       // distinct states of the fold entered (states of abort not counted)
  std::uint32_t transitions = 0;
  double fold_time_s = 0;    // from the start to done or aborted
  Score score;
  bool hands_clear = false;  // at the end (world truth): no fingertip or palm touching, every tip 20 mm up or more
  double min_tip_z_mm = 0;
  double max_force_n[2] = {0, 0};  // the largest fingertip normal force of each hand over the trial
  // How deep each arm's links, wrist and forearm reached under the table's top over the trial
  // (world_state; the world's arms are kinematic and pass through it, a real one would not).
  double max_under_table_mm[2] = {0, 0};  // over 1 mm: no success
  bool success = false;
  std::string failure;       // the first reason it is not a success ("" for a success)
  std::vector<TimelineEntry> timeline;
  std::vector<SeriesSample> series;
  // The world's sheet (the truth grid) the score was taken from, world mm, row-major over u;
  // empty when no truth came.
  int sheet_nodes_u = 0, sheet_nodes_v = 0;
  std::vector<std::array<float, 3>> sheet_end_mm;
  std::string error;
};

// Runs one trial in this process (see above). Never throws: a configuration or start-up error
// is the result's `error` (end "error").
[[nodiscard]] TrialResult run_trial(const TrialOptions& options, int index, std::uint64_t seed);

// Whether the trial succeeded, and why not: the sequence done, the sheet's shape within the
// bounds, not torn, on the table, the hands clear.
void judge(TrialResult& r);

}  // namespace crease::trials
