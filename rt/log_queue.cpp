#include "rt/log_queue.h"

#include <chrono>

#include "rt/thread_placement.h"

namespace crease::rt {

bool RtLogQueue::try_log(LogLevel level, const char* source, const char* text, std::int64_t time_ns) noexcept {
  return try_log(level, source, text, time_ns, 0, 0, 0);
}

bool RtLogQueue::try_log(LogLevel level, const char* source, const char* text, std::int64_t time_ns, std::int64_t v0,
                         std::int64_t v1, std::uint8_t value_count) noexcept {
  LogRecord r;
  r.time_ns = time_ns;
  r.level = level;
  r.values[0] = v0;
  r.values[1] = v1;
  r.value_count = value_count > 2 ? 2 : value_count;
  copy_text(r.source, source);
  copy_text(r.text, text);
  return q_.try_push(&r);
}

std::string format_log_record(const LogRecord& r) {
  std::string s;
  if (r.source[0] != '\0') {
    s += r.source;
    s += ": ";
  }
  s += r.text;
  for (std::uint8_t i = 0; i < r.value_count; ++i) {
    s += ' ';
    s += std::to_string(r.values[i]);
  }
  return s;
}

LogDrain::LogDrain(Sink sink, int poll_ms) : sink_(std::move(sink)), poll_ms_(poll_ms) {
  thread_ = std::thread([this] {
    place_this_thread_non_rt("crease-log");
    run();
  });
}

LogDrain::~LogDrain() {
  {
    std::lock_guard lock(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
  flush();
}

void LogDrain::add(RtLogQueue* q) {
  std::lock_guard lock(mu_);
  queues_.push_back(q);
}

void LogDrain::remove(RtLogQueue* q) {
  std::lock_guard lock(mu_);
  LogRecord r;
  while (q->try_pop(r)) sink_(r);
  std::erase(queues_, q);
}

void LogDrain::flush() {
  std::lock_guard lock(mu_);
  LogRecord r;
  for (RtLogQueue* q : queues_) {
    while (q->try_pop(r)) sink_(r);
  }
}

void LogDrain::run() {
  std::unique_lock lock(mu_);
  while (!stop_) {
    cv_.wait_for(lock, std::chrono::milliseconds(poll_ms_));
    LogRecord r;
    for (RtLogQueue* q : queues_) {
      while (q->try_pop(r)) sink_(r);
    }
  }
}

}  // namespace crease::rt
