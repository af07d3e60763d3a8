// Marks threads as real-time and counts heap allocations made on them.
//
// Every loop thread marks itself RT. Counting needs the allocation hooks (library
// crease_rt_alloc_hooks, linked into creased, the tests and crease-bench): they replace the
// global operator new/delete and count calls made on RT-marked threads, in a process-wide
// total and in a per-thread counter the loops read around each plugin hook to attribute an
// allocation to the plugin that made it. On a thread that is not RT-marked a hooked
// allocation costs one thread_local test. malloc called directly (C code) is not counted.
#pragma once

#include <cstdint>

namespace crease::rt {

// Marks (or unmarks) the calling thread as real-time. RT-safe.
void mark_this_thread_rt(bool is_rt) noexcept;
[[nodiscard]] bool this_thread_is_rt() noexcept;

// Allocations (operator new, new[], and their aligned/nothrow forms) and frees made on
// RT-marked threads since the process started. Always 0 unless the hooks are linked.
[[nodiscard]] std::uint64_t rt_allocation_count() noexcept;
[[nodiscard]] std::uint64_t rt_free_count() noexcept;
// The calling thread's own count of allocations made while it was RT-marked: a pointer that
// stays valid for the thread's life, read by that thread only (a loop reads it before and
// after each hook: one load each, no call). RT-safe.
[[nodiscard]] const std::uint64_t* this_thread_rt_allocations() noexcept;
// True when crease_rt_alloc_hooks is linked in, i.e. the counts above mean something.
[[nodiscard]] bool alloc_hooks_installed() noexcept;

// Marks the calling thread RT for a scope (library tests: wrap the steady-state step).
class ScopedRtMark {
 public:
  ScopedRtMark() noexcept : was_rt_(this_thread_is_rt()) { mark_this_thread_rt(true); }
  ~ScopedRtMark() { mark_this_thread_rt(was_rt_); }
  ScopedRtMark(const ScopedRtMark&) = delete;
  ScopedRtMark& operator=(const ScopedRtMark&) = delete;

 private:
  bool was_rt_;
};

namespace detail {
// Called by the hooks; not for general use.
void note_rt_allocation() noexcept;
void note_rt_free() noexcept;
void note_hooks_installed() noexcept;
}  // namespace detail

}  // namespace crease::rt
