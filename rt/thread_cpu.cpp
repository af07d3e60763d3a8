#include "rt/thread_cpu.h"

#include <sys/resource.h>

#include <algorithm>

#include "rt/clock.h"

namespace crease::rt {

ThreadCpuSample sample_thread_cpu() noexcept {
  ThreadCpuSample s;
  rusage ru{};
  timespec cpu{};
  const bool have_switches = getrusage(RUSAGE_THREAD, &ru) == 0;
  const bool have_cpu = clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu) == 0;
  s.wall_ns = now_ns();
  s.voluntary = have_switches ? ru.ru_nvcsw : -1;
  s.cpu_ns = have_cpu ? std::int64_t{cpu.tv_sec} * kNsPerS + cpu.tv_nsec : -1;
  return s;
}

std::int64_t charged_hook_ns(std::int64_t hook_ns, const ThreadCpuSample& cycle_start,
                             const ThreadCpuSample& now) noexcept {
  if (now.voluntary < 0 || cycle_start.voluntary < 0 || now.cpu_ns < 0 || cycle_start.cpu_ns < 0) return hook_ns;
  if (now.voluntary != cycle_start.voluntary) return hook_ns;  // it blocked: all of it counts
  const std::int64_t off_cpu = (now.wall_ns - cycle_start.wall_ns) - (now.cpu_ns - cycle_start.cpu_ns);
  return std::clamp<std::int64_t>(hook_ns - std::max<std::int64_t>(off_cpu, 0), 0, hook_ns);
}

}  // namespace crease::rt
