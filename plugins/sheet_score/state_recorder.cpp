#include "plugins/sheet_score/state_recorder.h"

#include <chrono>
#include <cstdio>
#include <cstring>

#include "core/errors.h"

namespace crease::sheet_score {

StateRecorder::StateRecorder(const std::string& path, std::int64_t start_ns, std::size_t queue_frames)
    : out_(path, std::ios::out | std::ios::trunc),
      start_ns_(start_ns),
      queue_(sizeof(Frame), queue_frames),
      staging_(std::make_unique<Frame>()),
      writing_(std::make_unique<Frame>()) {
  if (!out_) throw crease::Error("cannot write '" + path + "'");
  thread_ = std::thread([this] { run(); });
}

StateRecorder::~StateRecorder() { stop(); }

bool StateRecorder::record_rt(const SheetState& s) noexcept {
  const std::size_t n = static_cast<std::size_t>(s.nodes_u) * s.nodes_v;
  if (n == 0 || n > SheetState::kMaxNodes) return false;  // no sheet: nothing to record
  Frame& f = *staging_;
  f.timestamp_ns = s.timestamp_ns;
  f.step = s.step;
  f.nodes_u = s.nodes_u;
  f.nodes_v = s.nodes_v;
  f.width_mm = s.width_mm;
  f.height_mm = s.height_mm;
  std::memcpy(f.position_mm, s.position_mm, n * sizeof(f.position_mm[0]));
  return queue_.try_push(&f);
}

void StateRecorder::stop() {
  if (stop_.exchange(true)) return;
  thread_.join();
  drain();
  out_.flush();
}

void StateRecorder::run() {
  // A 60 Hz model fills the 32-frame queue in half a second; draining every 10 ms keeps it empty.
  while (!stop_.load(std::memory_order_relaxed)) {
    drain();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void StateRecorder::drain() {
  Frame& f = *writing_;
  while (queue_.try_pop(&f)) {
    char buf[192];
    std::snprintf(buf, sizeof(buf),
                  "{\"t\":%.6f,\"stamp_ns\":%lld,\"frame\":%llu,\"grid\":[%u,%u],\"size_mm\":[%.3f,%.3f],\"nodes\":[",
                  double(f.timestamp_ns - start_ns_) * 1e-9, static_cast<long long>(f.timestamp_ns),
                  static_cast<unsigned long long>(f.step), f.nodes_u, f.nodes_v, f.width_mm, f.height_mm);
    out_ << buf;
    const std::size_t n = static_cast<std::size_t>(f.nodes_u) * f.nodes_v;
    for (std::size_t k = 0; k < n; ++k) {
      std::snprintf(buf, sizeof(buf), "%s[%.3f,%.3f,%.3f]", k ? "," : "", f.position_mm[k][0], f.position_mm[k][1],
                    f.position_mm[k][2]);
      out_ << buf;
    }
    out_ << "]}\n";
    recorded_.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace crease::sheet_score
