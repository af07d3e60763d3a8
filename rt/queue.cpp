#include "rt/queue.h"

#include <bit>
#include <cstring>

namespace crease::rt {

QueueChannel::QueueChannel(std::size_t record_size, std::size_t capacity)
    : record_size_(record_size),
      mask_(std::bit_ceil(capacity < 1 ? std::size_t{1} : capacity) - 1),
      storage_(new unsigned char[(mask_ + 1) * record_size]()) {}

bool QueueChannel::try_push(const void* record) noexcept {
  const std::size_t tail = tail_.load(std::memory_order_relaxed);
  if (tail - cached_head_ > mask_) {
    cached_head_ = head_.load(std::memory_order_acquire);
    if (tail - cached_head_ > mask_) {
      // Single producer: a plain increment, no locked instruction.
      dropped_.store(dropped_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
      return false;
    }
  }
  std::memcpy(storage_.get() + (tail & mask_) * record_size_, record, record_size_);
  tail_.store(tail + 1, std::memory_order_release);
  pushed_.store(pushed_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  return true;
}

bool QueueChannel::try_pop(void* out) noexcept {
  const std::size_t head = head_.load(std::memory_order_relaxed);
  if (head == cached_tail_) {
    cached_tail_ = tail_.load(std::memory_order_acquire);
    if (head == cached_tail_) return false;
  }
  std::memcpy(out, storage_.get() + (head & mask_) * record_size_, record_size_);
  head_.store(head + 1, std::memory_order_release);
  return true;
}

std::size_t QueueChannel::size_approx() const noexcept {
  const std::size_t tail = tail_.load(std::memory_order_acquire);
  const std::size_t head = head_.load(std::memory_order_acquire);
  return tail >= head ? tail - head : 0;
}

}  // namespace crease::rt
