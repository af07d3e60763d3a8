// TactileReader: the tactile matrix's serial link (drivers/README.md §6) served by a
// non-real-time thread of its own, so that a loop's update never makes a syscall on the tty.
//
//   thread (named, on the non-RT CPUs: rt/thread_placement.h;   update (RT)
//   SCHED_FIFO cfg.thread_priority where permitted)
//     wait for bytes (SerialIo::read_wait), deframe, decode   take_rt(now): pops every queued
//     each Sample -> queue (rt/queue.h, SPSC, kQueueCapacity)   sample, keeps the newest
//     Start while no sample arrives (and every retry period)    health(now), counters()
//
// Every decoded sample goes through the queue in order; take_rt takes them all, so at the
// sensor's rate none is lost. A queue the RT side has not emptied for kQueueCapacity samples
// (256 ms at 250 Hz) drops the newer ones, counted as overruns. A sample's reception time is
// the time of the RT side's call that took it (the loop's clock, as the rest of a cycle's
// state), so its age and the link's health are in the loop's time.
// Why real-time: at SCHED_OTHER the thread waited behind the process's own renderers and the
// machine's other work, and config.sim_sequence saw the taxels 100 ms and more old (a link
// fault to contact_r, the folding sequence aborted) while the world wrote them on time. The
// thread blocks in poll() between samples (woken by the bytes, or by stop), so it costs a CPU
// only for the read and the deframing.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <thread>

#include "drivers/host/link_monitor.h"
#include "drivers/host/tactile_host.h"
#include "drivers/protocol/tactile_protocol.h"
#include "drivers/serial/serial_io.h"
#include "rt/queue.h"

namespace crease::drivers {

// What the link has done so far. Monotonic counts.
struct TactileCounters {
  std::uint64_t frames = 0;      // samples the RT side took
  std::uint64_t crc_errors = 0;  // frames dropped by the deframer: bad CRC or bad COBS
  std::uint64_t overruns = 0;    // samples dropped because the queue was full
};

class TactileReader {
 public:
  static constexpr std::size_t kQueueCapacity = 64;
  static constexpr int kWaitMs = 10;  // the thread's longest wait: Start retries, stop

  // Non-RT: allocates the queue; starts nothing. `thread_name` at most 15 characters.
  TactileReader(std::unique_ptr<SerialIo> io, const TactileHostConfig& cfg, const char* thread_name);
  ~TactileReader();  // stops the thread
  TactileReader(const TactileReader&) = delete;
  TactileReader& operator=(const TactileReader&) = delete;

  // Non-RT: start the thread (no-op when running) / wake it, wait for it to end.
  void start();
  void stop();

  // RT: takes every sample the thread queued since the last call, received at now_ns; true
  // when one arrived. No syscall, no allocation, no lock.
  bool take_rt(std::int64_t now_ns) noexcept;
  [[nodiscard]] const tactile::Sample& sample() const noexcept { return held_[front_].sample; }
  [[nodiscard]] std::int64_t sample_rx_ns() const noexcept { return held_[front_].rx_ns; }
  [[nodiscard]] std::uint64_t samples() const noexcept { return taken_; }
  [[nodiscard]] LinkHealth health(std::int64_t now_ns) const noexcept;
  // Any thread (the RT side's frames are exact on the RT side).
  [[nodiscard]] TactileCounters counters() const noexcept;
  // Any thread: whether the thread has sent a Start yet (its write went through).
  [[nodiscard]] bool started() const noexcept { return started_.load(std::memory_order_acquire); }
  // Any thread: whether the running thread took SCHED_FIFO cfg.thread_priority (false while
  // it has not tried yet, was not permitted, or the priority is 0).
  [[nodiscard]] bool fifo() const noexcept { return fifo_.load(std::memory_order_acquire); }

 private:
  struct Record {
    tactile::Sample sample;
    std::int64_t rx_ns = 0;  // the thread's clock in the queue; the RT side's once taken
  };
  void run();
  void send_start(std::int64_t now_ns);

  std::unique_ptr<SerialIo> io_;
  TactileHostConfig cfg_;
  const char* name_;
  rt::QueueChannel queue_;
  // The thread's own.
  SerialDeframer deframer_;
  std::uint8_t rx_[1024] = {};
  std::uint8_t tx_[kSerialMaxWire] = {};
  std::uint8_t tx_seq_ = 0;
  std::int64_t last_rx_ns_ = 0, last_start_ns_ = 0;
  bool any_rx_ = false;
  // Shared.
  std::atomic<std::uint64_t> framing_errors_{0};
  std::atomic<std::uint64_t> taken_shared_{0};
  std::atomic<bool> started_{false};
  std::atomic<bool> fifo_{false};
  std::atomic<bool> stop_{false};
  std::thread thread_;
  // The RT side's own.
  Record held_[2];
  int front_ = 0;
  std::uint64_t taken_ = 0;
};

}  // namespace crease::drivers
