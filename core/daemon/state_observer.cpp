#include "core/daemon/state_observer.h"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/errors.h"

namespace crease::daemon {

StateObserver::StateObserver(const PortRegistry& ports, std::string record_path, std::int64_t start_ns)
    : ports_(ports), start_ns_(start_ns), state_(std::make_unique<SheetState>()), truth_(std::make_unique<SheetState>()) {
  if (!record_path.empty()) {
    record_.open(record_path, std::ios::out | std::ios::trunc);
    if (!record_) throw Error("--record-state: cannot write '" + record_path + "'");
    recording_ = true;
  }
  thread_ = std::thread([this] { run(); });
}

StateObserver::~StateObserver() { stop(); }

void StateObserver::stop() {
  if (stop_.exchange(true)) return;
  thread_.join();
  poll_once();  // the last frame
  if (recording_) record_.flush();
}

void StateObserver::run() {
  // 4 polls per 60 Hz model frame: a frame is missed only when this thread is starved.
  while (!stop_.load()) {
    poll_once();
    std::this_thread::sleep_for(std::chrono::microseconds(4000));
  }
}

void StateObserver::poll_once() {
  const rt::LatestChannel* state_ch = ports_.find_latest("sheet_state");
  if (state_ch == nullptr || state_ch->payload_size() != sizeof(SheetState)) return;
  const rt::ReadInfo info = state_ch->read(state_.get(), last_seq_);
  if (!info.is_new()) return;
  const std::uint64_t missed = last_seq_ != 0 && info.seq > last_seq_ + 1 ? info.seq - last_seq_ - 1 : 0;
  last_seq_ = info.seq;
  const SheetState& s = *state_;
  const std::size_t n = static_cast<std::size_t>(s.nodes_u) * s.nodes_v;
  if (n == 0 || n > SheetState::kMaxNodes) return;  // the safe value: no sheet

  bool scored = false;
  double err = 0;
  if (const rt::LatestChannel* truth_ch = ports_.find_latest("sheet_truth");
      truth_ch != nullptr && truth_ch->payload_size() == sizeof(SheetState)) {
    const rt::ReadInfo t = truth_ch->read(truth_.get(), truth_seq_);
    if (t.has_data()) truth_seq_ = t.seq;
    if (t.has_data() && truth_->nodes_u == s.nodes_u && truth_->nodes_v == s.nodes_v) {
      for (std::size_t k = 0; k < n; ++k) {
        const double dx = s.position_mm[k][0] - truth_->position_mm[k][0];
        const double dy = s.position_mm[k][1] - truth_->position_mm[k][1];
        const double dz = s.position_mm[k][2] - truth_->position_mm[k][2];
        err += std::sqrt(dx * dx + dy * dy + dz * dz);
      }
      err /= double(n);
      scored = true;
    }
  }
  if (recording_) {
    char buf[96];
    std::snprintf(buf, sizeof(buf), "{\"t\":%.6f,\"frame\":%llu,\"grid\":[%u,%u],\"size_mm\":[%.3f,%.3f],\"nodes\":[",
                  double(s.timestamp_ns - start_ns_) * 1e-9, (unsigned long long)s.step, s.nodes_u, s.nodes_v,
                  s.width_mm, s.height_mm);
    record_ << buf;
    for (std::size_t k = 0; k < n; ++k) {
      std::snprintf(buf, sizeof(buf), "%s[%.3f,%.3f,%.3f]", k ? "," : "", s.position_mm[k][0], s.position_mm[k][1],
                    s.position_mm[k][2]);
      record_ << buf;
    }
    record_ << "]}\n";
  }
  std::lock_guard lock(mu_);
  summary_.missed += missed;
  if (recording_) summary_.recorded++;
  if (scored) {
    summary_.scored = true;
    summary_.frames++;
    sum_mm_ += err;
    window_sum_mm_ += err;
    window_frames_++;
    summary_.last_mm = err;
    summary_.max_mm = std::max(summary_.max_mm, err);
    summary_.mean_mm = sum_mm_ / double(summary_.frames);
  }
}

TrackingSummary StateObserver::take_window() {
  std::lock_guard lock(mu_);
  TrackingSummary s = summary_;
  s.window_mean_mm = window_frames_ ? window_sum_mm_ / double(window_frames_) : 0.0;
  window_sum_mm_ = 0;
  window_frames_ = 0;
  return s;
}

TrackingSummary StateObserver::summary() const {
  std::lock_guard lock(mu_);
  return summary_;
}

}  // namespace crease::daemon
