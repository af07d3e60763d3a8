// candump -L log files: one frame per line, "(SEC.USEC) IFACE ID#DATA".
//   classic: 123#11223344      extended: 12345678#11      RTR: 123#R (or 123#R5 with a length)
//   FD:      123##<flags hex nibble><data>               error frames: 8-digit id with 0x20000000
// Written and read by can-utils (candump -L, canplayer, log2asc) and python-can's CanutilsLogReader.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

#include "drivers/can/can_bus.h"

namespace crease::drivers {

struct CandumpEntry {
  std::int64_t timestamp_ns = 0;  // as written in the log (seconds.microseconds)
  char interface[16] = {};
  CanFrame frame;
};

// Formats one line (no newline) into buf; returns its length, or 0 if it does not fit.
// RT-safe: no allocation.
std::size_t format_candump_line(const CandumpEntry& e, char* buf, std::size_t cap) noexcept;
// Parses one line (trailing newline/space allowed). False on any malformed field.
[[nodiscard]] bool parse_candump_line(std::string_view line, CandumpEntry& out) noexcept;

// Appends lines to a file. Not RT (stdio). Throws std::runtime_error naming the file.
class CandumpWriter {
 public:
  explicit CandumpWriter(const std::string& path);
  ~CandumpWriter();
  CandumpWriter(const CandumpWriter&) = delete;
  CandumpWriter& operator=(const CandumpWriter&) = delete;
  void write(const CandumpEntry& e);
  void flush();

 private:
  std::string path_;
  std::FILE* f_;
};

// Reads a log. next() returns false at end of file; a malformed line throws
// std::runtime_error naming the file and line number.
class CandumpReader {
 public:
  explicit CandumpReader(const std::string& path);
  ~CandumpReader();
  CandumpReader(const CandumpReader&) = delete;
  CandumpReader& operator=(const CandumpReader&) = delete;
  [[nodiscard]] bool next(CandumpEntry& out);

 private:
  std::string path_;
  std::FILE* f_;
  int line_ = 0;
};

struct ReplayStats {
  std::size_t sent = 0;
  std::uint64_t waits = 0;  // pauses for room on the bus (a no_buffers answer each)
};

// Replays a log onto a bus, keeping the recorded inter-frame gaps (from the first frame)
// scaled by 1/speed (speed <= 0: as fast as the bus takes them). A full transmit queue
// (no_buffers) is waited out, however long it lasts, pausing 20 us doubling to 1 ms between
// tries; the replay gives up only if the bus is gone (its fd hung up or failed) or bus-off
// or broken (std::runtime_error naming the frame). `pause_ns` is how it pauses (nullptr:
// nanosleep), for tests. Returns frames sent.
std::size_t replay_candump(CandumpReader& log, CanBus& bus, double speed, ReplayStats* stats = nullptr,
                           void (*pause_ns)(std::int64_t) = nullptr);

}  // namespace crease::drivers
