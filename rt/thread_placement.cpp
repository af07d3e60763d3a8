#include "rt/thread_placement.h"

#include <dirent.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>

namespace crease::rt {
namespace {

std::mutex g_mutex;           // guards the two sets below (non-RT code only)
std::vector<int> g_non_rt;    // the recorded non-RT set
std::vector<int> g_process;   // the process's CPUs at the first look
bool g_process_known = false;

std::vector<int> cpus_of(const cpu_set_t& set) {
  std::vector<int> out;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) out.push_back(c);
  return out;
}

bool to_set(const std::vector<int>& cpus, cpu_set_t& set) {
  CPU_ZERO(&set);
  for (int c : cpus) {
    if (c < 0 || c >= CPU_SETSIZE) return false;
    CPU_SET(c, &set);
  }
  return !cpus.empty();
}

const char* policy_name(int policy) {
  switch (policy) {
    case SCHED_FIFO: return "fifo";
    case SCHED_RR: return "rr";
    case SCHED_BATCH: return "batch";
    case SCHED_IDLE: return "idle";
    default: return "other";
  }
}

}  // namespace

std::vector<int> parse_cpu_list(const std::string& text) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    int a = 0, b = 0;
    char extra = 0;
    if (std::sscanf(part.c_str(), "%d-%d%c", &a, &b, &extra) == 2 && a >= 0 && b >= a && b < CPU_SETSIZE) {
      for (int c = a; c <= b; ++c) out.push_back(c);
    } else if (std::sscanf(part.c_str(), "%d%c", &a, &extra) == 1 && a >= 0 && a < CPU_SETSIZE) {
      out.push_back(a);
    } else {
      return {};
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string format_cpu_list(const std::vector<int>& cpus) {
  std::string out;
  for (std::size_t i = 0; i < cpus.size();) {
    std::size_t j = i;
    while (j + 1 < cpus.size() && cpus[j + 1] == cpus[j] + 1) ++j;
    if (!out.empty()) out += ',';
    out += std::to_string(cpus[i]);
    if (j > i) out += '-' + std::to_string(cpus[j]);
    i = j + 1;
  }
  return out;
}

std::vector<int> process_cpus() {
  std::lock_guard lock(g_mutex);
  if (!g_process_known) {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof(set), &set) == 0) g_process = cpus_of(set);
    g_process_known = true;
  }
  return g_process;
}

SetupStep set_non_rt_cpus(const std::vector<int>& cpus) {
  (void)process_cpus();  // remember the process's CPUs before the first placement
  SetupStep step{"non-real-time threads on CPUs " + (cpus.empty() ? std::string("(any)") : format_cpu_list(cpus)),
                 false, {}, SetupStep::Kind::affinity};
  cpu_set_t set;
  if (!to_set(cpus, set)) {
    step.why = cpus.empty() ? "no CPU is left to non-real-time work: they share the loops' CPUs"
                            : "a CPU index is out of range: they run anywhere";
    return step;
  }
  const int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
  if (rc != 0) {
    step.why = std::string(std::strerror(rc)) + ": they run anywhere";
    return step;
  }
  std::lock_guard lock(g_mutex);
  g_non_rt = cpus;
  step.applied = true;
  return step;
}

std::vector<int> non_rt_cpus() {
  std::lock_guard lock(g_mutex);
  return g_non_rt;
}

void place_this_thread_non_rt(const char* name) noexcept {
  char shortened[16] = {};
  std::strncpy(shortened, name, sizeof(shortened) - 1);
  pthread_setname_np(pthread_self(), shortened);
  cpu_set_t set;
  bool have = false;
  {
    std::lock_guard lock(g_mutex);
    have = to_set(g_non_rt, set);
  }
  if (have) (void)pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
}

std::vector<ThreadInfo> list_threads() {
  std::vector<ThreadInfo> out;
  DIR* dir = opendir("/proc/self/task");
  if (dir == nullptr) return out;
  while (const dirent* e = readdir(dir)) {
    if (e->d_name[0] < '0' || e->d_name[0] > '9') continue;
    ThreadInfo t;
    t.tid = std::atoi(e->d_name);
    const std::string base = std::string("/proc/self/task/") + e->d_name;
    std::ifstream comm(base + "/comm");
    std::getline(comm, t.name);
    std::ifstream stat(base + "/stat");
    std::string line;
    std::getline(stat, line);
    // Field 39 (processor) counts from after the ')' that closes the name, field 3 onwards.
    const std::size_t close = line.rfind(')');
    if (close != std::string::npos) {
      std::istringstream fields(line.substr(close + 2));
      std::string f;
      for (int i = 3; i <= 39 && fields >> f; ++i)
        if (i == 39) t.last_cpu = std::atoi(f.c_str());
    }
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(t.tid, sizeof(set), &set) == 0) t.cpus = cpus_of(set);
    const int policy = sched_getscheduler(t.tid);
    t.policy = policy_name(policy < 0 ? SCHED_OTHER : policy);
    sched_param sp{};
    if (sched_getparam(t.tid, &sp) == 0) t.priority = sp.sched_priority;
    out.push_back(std::move(t));
  }
  closedir(dir);
  std::sort(out.begin(), out.end(), [](const ThreadInfo& a, const ThreadInfo& b) { return a.tid < b.tid; });
  return out;
}

}  // namespace crease::rt
