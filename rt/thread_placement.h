// Where the process's non-real-time threads run: the CPUs the real-time loops leave free.
//
//   rt::set_non_rt_cpus({0});                 // once, at start-up, before threads are made
//   rt::place_this_thread_non_rt("ctl-io");   // first line of every non-RT thread we own
//   for (const rt::ThreadInfo& t : rt::list_threads()) ...   // every thread of the process
//
// set_non_rt_cpus also moves the calling thread there, so every thread it creates later
// inherits the set (Linux threads start with their creator's affinity); a real-time loop pins
// itself to its own CPU (apply_thread_settings). place_this_thread_non_rt names the thread
// (at most 15 characters, what `top -H` and the threads view show) and applies the set
// explicitly, for threads created by a thread that is not itself non-RT. Nothing here throws
// on refusal: the outcome says what happened. Non-RT: none of this is for a loop's update.
#pragma once

#include <string>
#include <vector>

#include "rt/rt_setup.h"

namespace crease::rt {

// Parses "0,2-3" (a CPU list as the kernel prints it); empty on a malformed list.
[[nodiscard]] std::vector<int> parse_cpu_list(const std::string& text);
// Formats a sorted CPU set as a CPU list ("0,2-3").
[[nodiscard]] std::string format_cpu_list(const std::vector<int>& cpus);
// The CPUs this process may use (its affinity at the first call, before any placement).
[[nodiscard]] std::vector<int> process_cpus();

// Records CPUS as the non-RT set and moves the calling thread onto it. An empty set (or one
// the kernel refuses) leaves threads where they are; the step says why.
SetupStep set_non_rt_cpus(const std::vector<int>& cpus);
// The non-RT set recorded by set_non_rt_cpus; empty when none was set.
[[nodiscard]] std::vector<int> non_rt_cpus();

// Names the calling thread and moves it onto the non-RT set (when one is set).
void place_this_thread_non_rt(const char* name) noexcept;

// One thread of this process, read from /proc/self/task and the scheduler.
struct ThreadInfo {
  int tid = 0;
  std::string name;          // its comm (pthread_setname_np)
  std::vector<int> cpus;     // its affinity
  int last_cpu = -1;         // the CPU it last ran on
  std::string policy;        // "fifo", "rr", "other", "batch", "idle"
  int priority = 0;          // SCHED_FIFO / RR priority, 0 otherwise
};
[[nodiscard]] std::vector<ThreadInfo> list_threads();

}  // namespace crease::rt
