// `queue` channel: a bounded single-producer single-consumer ring of fixed-size records.
//
// try_push copies a record in and never blocks: when the ring is full the record is dropped and
// counted. try_pop copies the oldest record out. Both are wait-free. Records are bytes
// (type-erased) so the channel outlives the plugin library that pushed into it; the typed ends
// below give T-shaped access. Capacity is rounded up to a power of two.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>

namespace crease::rt {

class QueueChannel {
 public:
  // Allocates the ring now (non-RT). record_size > 0, capacity >= 1.
  QueueChannel(std::size_t record_size, std::size_t capacity);
  QueueChannel(const QueueChannel&) = delete;
  QueueChannel& operator=(const QueueChannel&) = delete;

  [[nodiscard]] std::size_t record_size() const noexcept { return record_size_; }
  [[nodiscard]] std::size_t capacity() const noexcept { return mask_ + 1; }

  // Producer only. False (and the record counted as dropped) when full.
  [[nodiscard]] bool try_push(const void* record) noexcept;
  // Consumer only. False when empty.
  [[nodiscard]] bool try_pop(void* out) noexcept;

  // Approximate from any thread; exact from the consumer's side for "is there more".
  [[nodiscard]] std::size_t size_approx() const noexcept;
  [[nodiscard]] std::uint64_t pushed() const noexcept { return pushed_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::size_t record_size_;
  std::size_t mask_;
  std::unique_ptr<unsigned char[]> storage_;
  // head_ (consumer) and tail_ (producer) on their own cache lines: no false sharing between the
  // two threads. Each side caches the other's index to touch the shared line only when needed.
  alignas(64) std::atomic<std::size_t> head_{0};
  std::size_t cached_tail_ = 0;  // consumer's copy
  alignas(64) std::atomic<std::size_t> tail_{0};
  std::size_t cached_head_ = 0;  // producer's copy
  std::atomic<std::uint64_t> pushed_{0};
  std::atomic<std::uint64_t> dropped_{0};
};

template <class T>
class QueueWriter {
  static_assert(std::is_trivially_copyable_v<T>, "queue records are plain structs");

 public:
  QueueWriter() = default;
  explicit QueueWriter(QueueChannel* ch) noexcept : ch_(ch) {}
  [[nodiscard]] bool try_push(const T& v) noexcept { return ch_->try_push(&v); }
  [[nodiscard]] bool bound() const noexcept { return ch_ != nullptr; }

 private:
  QueueChannel* ch_ = nullptr;
};

template <class T>
class QueueReader {
  static_assert(std::is_trivially_copyable_v<T>, "queue records are plain structs");

 public:
  QueueReader() = default;
  explicit QueueReader(QueueChannel* ch) noexcept : ch_(ch) {}
  [[nodiscard]] bool try_pop(T& out) noexcept { return ch_->try_pop(&out); }
  [[nodiscard]] bool bound() const noexcept { return ch_ != nullptr; }

 private:
  QueueChannel* ch_ = nullptr;
};

}  // namespace crease::rt
