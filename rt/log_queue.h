// Logging from RT threads: fixed-size records pushed to a per-thread SPSC queue, formatted and
// written by a non-RT drain thread. Pushing copies a few bytes and never blocks; a full queue
// drops the record and counts it.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "rt/queue.h"

namespace crease::rt {

// mark: a moment of the run for its report's timeline (the plugin host records it as an event of
// the instance, with the record's time; logged at info).
enum class LogLevel : std::uint8_t { debug, info, warn, error, mark };

struct LogRecord {
  std::int64_t time_ns = 0;   // CLOCK_MONOTONIC
  std::int64_t values[2] = {0, 0};
  LogLevel level = LogLevel::info;
  std::uint8_t value_count = 0;
  char source[30] = {};       // e.g. the plugin instance name (truncated)
  char text[96] = {};         // a message (truncated); values are appended when formatted
};
static_assert(std::is_trivially_copyable_v<LogRecord> && sizeof(LogRecord) <= 160, "log records are small plain structs");

// Copies at most N-1 characters and terminates: RT-safe strncpy.
template <std::size_t N>
inline void copy_text(char (&dst)[N], const char* src) noexcept {
  std::size_t i = 0;
  if (src != nullptr) {
    for (; i + 1 < N && src[i] != '\0'; ++i) dst[i] = src[i];
  }
  dst[i] = '\0';
}

// One producer (an RT thread), one consumer (the drain).
class RtLogQueue {
 public:
  explicit RtLogQueue(std::size_t capacity = 256) : q_(sizeof(LogRecord), capacity) {}

  // RT-safe. False when the queue is full (the record is counted as dropped).
  bool try_log(LogLevel level, const char* source, const char* text, std::int64_t time_ns) noexcept;
  bool try_log(LogLevel level, const char* source, const char* text, std::int64_t time_ns, std::int64_t v0,
               std::int64_t v1 = 0, std::uint8_t value_count = 1) noexcept;

  [[nodiscard]] bool try_pop(LogRecord& out) noexcept { return q_.try_pop(&out); }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return q_.dropped(); }

 private:
  QueueChannel q_;
};

// "source: text [v0 v1]" as one line.
std::string format_log_record(const LogRecord& r);

// Non-RT thread that drains every registered queue every `poll_ms` and hands each record to
// the sink. Queues are registered before or while it runs; they must outlive the drain.
class LogDrain {
 public:
  using Sink = std::function<void(const LogRecord&)>;
  LogDrain(Sink sink, int poll_ms = 20);
  ~LogDrain();  // drains what is left, then stops
  void add(RtLogQueue* q);
  void remove(RtLogQueue* q);  // drains q once more first
  void flush();                // drains everything now, on the caller's thread

 private:
  void run();
  Sink sink_;
  int poll_ms_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<RtLogQueue*> queues_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace crease::rt
