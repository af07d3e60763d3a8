#include "rt/rt_setup.h"

#include <fcntl.h>
#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

namespace crease::rt {
namespace {

std::string errno_text(int err) { return std::string(std::strerror(err)) + " (errno " + std::to_string(err) + ")"; }

// Touches `bytes` of this thread's stack so the pages are resident before the first cycle.
__attribute__((noinline)) void prefault_stack(std::size_t bytes) {
  constexpr std::size_t kChunk = 16 * 1024;
  unsigned char buf[kChunk];
  for (std::size_t i = 0; i < kChunk; i += 4096) buf[i] = 0;
  asm volatile("" : : "r"(buf) : "memory");  // keep the writes: they are the point
  if (bytes > kChunk) prefault_stack(bytes - kChunk);
}

}  // namespace

std::vector<SetupStep> apply_thread_settings(const std::string& name, const ThreadSettings& s) {
  std::vector<SetupStep> steps;
  if (s.priority > 0) {
    SetupStep step{"SCHED_FIFO priority " + std::to_string(s.priority) + " for loop '" + name + "'", false, {}, SetupStep::Kind::sched_fifo};
    sched_param sp{};
    sp.sched_priority = s.priority;
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
    if (rc == 0) {
      step.applied = true;
    } else {
      step.why = errno_text(rc) +
                 (rc == EPERM ? ": needs CAP_SYS_NICE or an rtprio limit (ulimit -r); the loop runs SCHED_OTHER"
                              : ": the loop runs SCHED_OTHER");
    }
    steps.push_back(std::move(step));
  }
  if (s.cpu >= 0) {
    SetupStep step{"CPU affinity " + std::to_string(s.cpu) + " for loop '" + name + "'", false, {}, SetupStep::Kind::affinity};
    cpu_set_t set;
    CPU_ZERO(&set);
    if (s.cpu >= CPU_SETSIZE) {
      step.why = "CPU index out of range; the loop may run on any CPU";
    } else {
      CPU_SET(s.cpu, &set);
      const int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
      if (rc == 0) {
        step.applied = true;
      } else {
        step.why = errno_text(rc) + ": the loop may run on any CPU";
      }
    }
    steps.push_back(std::move(step));
  }
  if (s.stack_prefault_bytes > 0) {
    prefault_stack(s.stack_prefault_bytes);
    steps.push_back({"stack prefault " + std::to_string(s.stack_prefault_bytes / 1024) + " KiB for loop '" + name + "'", true, {},
                     SetupStep::Kind::stack_prefault});
  }
  return steps;
}

SetupStep lock_memory(std::size_t prefault_heap_bytes) {
  SetupStep step{"mlockall with " + std::to_string(prefault_heap_bytes >> 20) + " MiB heap prefault", false, {}, SetupStep::Kind::memory_lock};
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    const int err = errno;
    step.why = errno_text(err) +
               (err == EPERM || err == ENOMEM ? ": needs CAP_IPC_LOCK or a memlock limit (ulimit -l); pages may be swapped or fault"
                                              : "");
    return step;
  }
  // Keep freed memory in the process and avoid mmap for large blocks, then touch the heap once.
  mallopt(M_TRIM_THRESHOLD, -1);
  mallopt(M_MMAP_MAX, 0);
  if (prefault_heap_bytes > 0) {
    auto* p = static_cast<volatile unsigned char*>(std::malloc(prefault_heap_bytes));
    if (p != nullptr) {
      for (std::size_t i = 0; i < prefault_heap_bytes; i += 4096) p[i] = 0;
      std::free(const_cast<unsigned char*>(p));
    }
  }
  step.applied = true;
  return step;
}

DmaLatencyRequest::~DmaLatencyRequest() {
  if (fd_ >= 0) ::close(fd_);
}

SetupStep DmaLatencyRequest::request(int microseconds) {
  SetupStep step{"/dev/cpu_dma_latency " + std::to_string(microseconds) + " us", false, {}, SetupStep::Kind::dma_latency};
  const int fd = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    step.why = errno_text(errno) + ": CPU idle states are left to the kernel";
    return step;
  }
  const std::int32_t value = microseconds;
  if (::write(fd, &value, sizeof(value)) != sizeof(value)) {
    step.why = errno_text(errno) + ": CPU idle states are left to the kernel";
    ::close(fd);
    return step;
  }
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
  step.applied = true;
  return step;
}

bool this_thread_is_fifo() noexcept {
  int policy = 0;
  sched_param sp{};
  return pthread_getschedparam(pthread_self(), &policy, &sp) == 0 && policy == SCHED_FIFO;
}

}  // namespace crease::rt
