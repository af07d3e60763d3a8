// StateRecorder: writes every sheet state handed to it as one JSON line, on its own non-RT
// thread, so any run can be scored offline:
//   {"t":…, "stamp_ns":…, "frame":…, "grid":[W,H], "size_mm":[w,h], "nodes":[[x,y,z],…]}
// t in seconds since the recorder started, stamp_ns the state's own CLOCK_MONOTONIC time
// (recordings of one run pair by it: recording_score.h), node positions in world mm, row by row. The RT side
// copies a frame into a bounded queue (record_rt); a frame that finds the queue full is counted
// as dropped, never written out of order or invented.
#pragma once

#include <atomic>
#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include "core/port_types/sheet_state.h"
#include "rt/queue.h"

namespace crease::sheet_score {

class StateRecorder {
 public:
  // Opens (truncates) path and starts the writer thread. Throws crease::Error when the
  // file cannot be written. start_ns: the recording's time origin (CLOCK_MONOTONIC).
  StateRecorder(const std::string& path, std::int64_t start_ns, std::size_t queue_frames = 32);
  ~StateRecorder();  // stop()
  StateRecorder(const StateRecorder&) = delete;
  StateRecorder& operator=(const StateRecorder&) = delete;

  // RT-safe: queues the frame; false (counted) when the queue is full.
  bool record_rt(const SheetState& s) noexcept;
  // Non-RT: writes what is queued, stops the thread, flushes. Idempotent.
  void stop();

  [[nodiscard]] std::uint64_t recorded() const noexcept { return recorded_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return queue_.dropped(); }

 private:
  struct Frame {  // what one line needs: the nodes only
    std::int64_t timestamp_ns;
    std::uint64_t step;
    std::uint32_t nodes_u, nodes_v;
    float width_mm, height_mm;
    float position_mm[SheetState::kMaxNodes][3];
  };
  void run();
  void drain();

  std::ofstream out_;
  std::int64_t start_ns_;
  rt::QueueChannel queue_;
  std::unique_ptr<Frame> staging_;  // RT side: the frame being queued
  std::unique_ptr<Frame> writing_;  // writer thread: the frame being written
  std::atomic<std::uint64_t> recorded_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace crease::sheet_score
