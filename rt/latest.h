// `latest` channel: the newest value of a piece of state, one writer, any number of readers.
//
// A ring of kSlots seqlocked slots. The writer fills the slot after the newest one and then
// publishes its sequence number: write is wait-free. A reader copies the newest slot and checks
// that the slot's sequence did not change while it copied; it retries (at most kMaxReadTries
// times) only if the writer lapped the whole ring during one copy, so reads are wait-free in
// practice and bounded always. Payload words are copied with release stores and acquire loads
// (plain moves on x86-64) so that the race a seqlock tolerates by design is not undefined
// behaviour, needs no fence, and ThreadSanitizer agrees.
// The channel is type-erased (bytes) so that it outlives the plugin library that wrote it.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <type_traits>

namespace crease::rt {

// What a read found (OROCOS's FlowStatus).
enum class Flow : std::uint8_t {
  no_data,   // never written
  old_data,  // the value the reader already saw
  new_data,  // a value newer than the reader last saw
};

struct ReadInfo {
  Flow flow = Flow::no_data;
  std::uint64_t seq = 0;      // 1 for the first value written, +1 per write; 0 = none
  std::int64_t stamp_ns = 0;  // writer's CLOCK_MONOTONIC timestamp of the value
  [[nodiscard]] bool has_data() const noexcept { return flow != Flow::no_data; }
  [[nodiscard]] bool is_new() const noexcept { return flow == Flow::new_data; }
};

class LatestChannel {
 public:
  static constexpr std::size_t kSlots = 8;  // a reader fails only if the writer laps all 8 during one copy
  static constexpr int kMaxReadTries = 64;

  // Allocates every slot now (non-RT). payload_size > 0.
  explicit LatestChannel(std::size_t payload_size);
  LatestChannel(const LatestChannel&) = delete;
  LatestChannel& operator=(const LatestChannel&) = delete;

  [[nodiscard]] std::size_t payload_size() const noexcept { return size_; }

  // Single writer. Wait-free, RT-safe. `data` points at payload_size() bytes.
  void write(const void* data, std::int64_t stamp_ns) noexcept;

  // Any thread. Copies the newest value into `out` (payload_size() bytes) when it is newer than
  // `last_seen_seq`; on old data copies nothing (the caller has it: LatestReader keeps it).
  // Bounded retries; RT-safe. If the writer kept lapping the reader for kMaxReadTries attempts,
  // returns old_data (no_data if last_seen_seq is 0) with last_seen_seq, and `out` may hold a
  // torn copy: read into a buffer that is not the value in use (LatestReader does).
  ReadInfo read(void* out, std::uint64_t last_seen_seq) const noexcept;

  // Newest published sequence number (0 = never written). Any thread.
  [[nodiscard]] std::uint64_t sequence() const noexcept {
    return latest_.load(std::memory_order_acquire);
  }
  // Reads that gave up after kMaxReadTries (should stay 0).
  [[nodiscard]] std::uint64_t read_give_ups() const noexcept {
    return give_ups_.load(std::memory_order_relaxed);
  }

 private:
  struct SlotHeader {
    std::atomic<std::uint64_t> seq{0};  // 2*version when stable, odd while being written
    std::atomic<std::int64_t> stamp_ns{0};
  };
  using Word = std::atomic<std::uint64_t>;
  static_assert(Word::is_always_lock_free);

  [[nodiscard]] SlotHeader& header(std::size_t i) const noexcept { return headers_[i]; }
  [[nodiscard]] Word* words(std::size_t i) const noexcept { return payload_.get() + i * words_; }

  std::size_t size_;
  std::size_t words_;  // payload words per slot (size rounded up to 8 bytes)
  std::unique_ptr<SlotHeader[]> headers_;
  std::unique_ptr<Word[]> payload_;
  // Separate cache line: readers poll it, the writer bumps it once per write.
  alignas(64) std::atomic<std::uint64_t> latest_{0};
  mutable std::atomic<std::uint64_t> give_ups_{0};
};

// Typed ends over a LatestChannel. T must be trivially copyable.
template <class T>
class LatestWriter {
  static_assert(std::is_trivially_copyable_v<T>, "port payloads are plain structs");

 public:
  LatestWriter() = default;
  explicit LatestWriter(LatestChannel* ch) noexcept : ch_(ch) {}
  void write(const T& v, std::int64_t stamp_ns) noexcept { ch_->write(&v, stamp_ns); }
  [[nodiscard]] bool bound() const noexcept { return ch_ != nullptr; }

 private:
  LatestChannel* ch_ = nullptr;
};

// The reading end keeps the newest value it has taken (value()), so a reader never has to
// remember to keep a copy: on a cycle with nothing new, value() is still the newest value.
// Two buffers: a copy that the writer tore (and that the channel retried or gave up on) lands
// in the back buffer and never reaches value().
template <class T>
class LatestReader {
  static_assert(std::is_trivially_copyable_v<T>, "port payloads are plain structs");

 public:
  LatestReader() = default;
  // Non-RT: allocates the reader's two buffers (value-initialised).
  explicit LatestReader(const LatestChannel* ch) : ch_(ch), bufs_(new T[2]{}) {}

  // RT-safe. Takes the newest value into value() when it is new to this reader and tells what it
  // found: no_data (never written: value() stays T{}), old_data (value() unchanged, info of the
  // value held), new_data (value() is the new value).
  ReadInfo poll() noexcept {
    const ReadInfo info = ch_->read(&bufs_[1 - front_], held_.seq);
    if (info.is_new()) {
      front_ = 1 - front_;
      held_ = info;
      return info;
    }
    if (held_.seq == 0) return ReadInfo{};
    ReadInfo old = held_;
    old.flow = Flow::old_data;
    return old;
  }
  // The newest value taken by poll() (T{} before any). Stable until the next poll().
  [[nodiscard]] const T& value() const noexcept { return bufs_[front_]; }
  // What the held value is: its sequence number (0 = none yet) and timestamp.
  [[nodiscard]] const ReadInfo& held() const noexcept { return held_; }
  [[nodiscard]] bool has_value() const noexcept { return held_.seq != 0; }
  [[nodiscard]] bool bound() const noexcept { return ch_ != nullptr; }

 private:
  const LatestChannel* ch_ = nullptr;
  std::unique_ptr<T[]> bufs_;
  int front_ = 0;
  ReadInfo held_{};
};

}  // namespace crease::rt
