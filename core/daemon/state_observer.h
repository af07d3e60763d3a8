// Watches the sheet ports from a non-RT thread: scores `sheet_state` against `sheet_truth`
// (mean node distance, mm) when both exist with the same grid, and records every model frame
// as one JSON line when asked (`creased --record-state FILE`):
//   {"t":…, "frame":…, "grid":[W,H], "size_mm":[w,h], "nodes":[[x,y,z],…]}
// t in seconds since the observer started, node positions in world mm, row by row. Frames the
// poller could not see (the model wrote twice between two polls) are counted, never invented.
#pragma once

#include <atomic>
#include <cstdint>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "core/port_registry.h"
#include "core/port_types/sheet_state.h"

namespace crease::daemon {

struct TrackingSummary {
  bool scored = false;          // both ports exist and match
  std::uint64_t frames = 0;     // model frames scored
  double mean_mm = 0;           // mean over all scored frames
  double last_mm = 0;           // the newest frame
  double window_mean_mm = 0;    // mean since the previous take_window() call
  double max_mm = 0;            // worst frame
  std::uint64_t recorded = 0;   // JSON lines written
  std::uint64_t missed = 0;     // model frames the poller did not see
};

class StateObserver {
 public:
  // record_path empty: no recording. Throws Error when the file cannot be opened.
  StateObserver(const PortRegistry& ports, std::string record_path, std::int64_t start_ns);
  ~StateObserver();  // stop()
  // Stops the thread, takes the newest frame once more, flushes the file. Idempotent.
  void stop();
  StateObserver(const StateObserver&) = delete;
  StateObserver& operator=(const StateObserver&) = delete;

  // The summary; resets the window mean.
  TrackingSummary take_window();
  [[nodiscard]] TrackingSummary summary() const;

 private:
  void run();
  void poll_once();

  const PortRegistry& ports_;
  std::int64_t start_ns_;
  std::ofstream record_;
  bool recording_ = false;
  std::unique_ptr<SheetState> state_, truth_;
  std::uint64_t last_seq_ = 0;
  std::uint64_t truth_seq_ = 0;
  double sum_mm_ = 0, window_sum_mm_ = 0;
  std::uint64_t window_frames_ = 0;
  mutable std::mutex mu_;  // guards summary_ and the window (non-RT threads only)
  TrackingSummary summary_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace crease::daemon
