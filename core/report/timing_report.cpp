#include "core/report/timing_report.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <thread>

#include <sys/utsname.h>
#include <unistd.h>

namespace crease::report {

void fill_percentiles(Distribution& d) {
  std::uint64_t total = 0;
  for (const Bucket& b : d.buckets) total += b.count;
  if (d.count == 0) d.count = total;
  const auto at = [&](double q) -> std::int64_t {
    if (total == 0) return 0;
    const auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(total)));
    std::uint64_t seen = 0;
    std::int64_t v = d.buckets.back().upper_ns;
    for (const Bucket& b : d.buckets) {
      seen += b.count;
      if (seen >= std::max<std::uint64_t>(rank, 1)) {
        v = b.upper_ns;
        break;
      }
    }
    if (d.max_ns > 0) v = std::clamp(v, d.min_ns, d.max_ns);
    return v;
  };
  d.p50_ns = at(0.50);
  d.p90_ns = at(0.90);
  d.p99_ns = at(0.99);
  d.p999_ns = at(0.999);
  d.p9999_ns = at(0.9999);
}

MachineInfo probe_machine() {
  MachineInfo m;
  utsname u{};
  if (::uname(&u) == 0) {
    m.hostname = u.nodename;
    m.kernel = std::string(u.sysname) + " " + u.release + " " + u.version + " " + u.machine;
    const std::string v = u.version;
    if (v.find("PREEMPT_RT") != std::string::npos) {
      m.preemption = "PREEMPT_RT";
    } else if (v.find("PREEMPT_DYNAMIC") != std::string::npos) {
      m.preemption = "PREEMPT_DYNAMIC";
    } else if (v.find("PREEMPT") != std::string::npos) {
      m.preemption = "PREEMPT";
    } else {
      m.preemption = "none";
    }
  }
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        m.cpu_model = line.substr(colon + 1);
        m.cpu_model.erase(0, m.cpu_model.find_first_not_of(" \t"));
      }
      break;
    }
  }
  m.cpu_count = static_cast<int>(std::thread::hardware_concurrency());
  return m;
}

}  // namespace crease::report
