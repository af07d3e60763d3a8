// Real-time setup of the process and of one thread: SCHED_FIFO priority, CPU affinity,
// mlockall with heap prefault, stack prefault, /dev/cpu_dma_latency.
//
// Each step is applied when permitted. When it is not, the step's outcome says which and why;
// the caller logs it (one line per step). Nothing here throws or aborts on refusal.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace crease::rt {

struct SetupStep {
  enum class Kind { sched_fifo, affinity, stack_prefault, memory_lock, dma_latency };
  std::string what;    // e.g. "SCHED_FIFO priority 80 for loop 'control'"
  bool applied = false;
  std::string why;     // when not applied: the reason (errno text and a hint)
  Kind kind = Kind::sched_fifo;
};

struct ThreadSettings {
  int priority = 0;  // 0 = SCHED_OTHER (no change), 1..99 = SCHED_FIFO
  int cpu = -1;      // -1 = any CPU
  std::size_t stack_prefault_bytes = 256 * 1024;
};

// Applies `s` to the calling thread. `name` appears in the step descriptions.
std::vector<SetupStep> apply_thread_settings(const std::string& name, const ThreadSettings& s);

// mlockall(MCL_CURRENT | MCL_FUTURE), then touches `prefault_heap_bytes` of heap so later
// allocations made off the RT threads do not page-fault (glibc keeps the trimmed memory).
SetupStep lock_memory(std::size_t prefault_heap_bytes);

// Holds a /dev/cpu_dma_latency request while alive (the kernel drops it when the fd closes).
class DmaLatencyRequest {
 public:
  DmaLatencyRequest() = default;
  ~DmaLatencyRequest();
  DmaLatencyRequest(const DmaLatencyRequest&) = delete;
  DmaLatencyRequest& operator=(const DmaLatencyRequest&) = delete;
  // Requests a maximum wake-up latency of `microseconds` for every CPU.
  SetupStep request(int microseconds);

 private:
  int fd_ = -1;
};

// Whether the calling thread runs SCHED_FIFO, for reports.
[[nodiscard]] bool this_thread_is_fifo() noexcept;

}  // namespace crease::rt
