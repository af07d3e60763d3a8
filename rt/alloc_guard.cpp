#include "rt/alloc_guard.h"

#include <atomic>

namespace crease::rt {
namespace {
thread_local bool t_is_rt = false;
thread_local std::uint64_t t_rt_allocs = 0;
std::atomic<std::uint64_t> g_rt_allocs{0};
std::atomic<std::uint64_t> g_rt_frees{0};
std::atomic<bool> g_hooks{false};
}  // namespace

void mark_this_thread_rt(bool is_rt) noexcept { t_is_rt = is_rt; }
bool this_thread_is_rt() noexcept { return t_is_rt; }
std::uint64_t rt_allocation_count() noexcept { return g_rt_allocs.load(std::memory_order_relaxed); }
std::uint64_t rt_free_count() noexcept { return g_rt_frees.load(std::memory_order_relaxed); }
const std::uint64_t* this_thread_rt_allocations() noexcept { return &t_rt_allocs; }
bool alloc_hooks_installed() noexcept { return g_hooks.load(std::memory_order_relaxed); }

namespace detail {
void note_rt_allocation() noexcept {
  if (t_is_rt) {
    ++t_rt_allocs;
    g_rt_allocs.fetch_add(1, std::memory_order_relaxed);
  }
}
void note_rt_free() noexcept {
  if (t_is_rt) g_rt_frees.fetch_add(1, std::memory_order_relaxed);
}
void note_hooks_installed() noexcept { g_hooks.store(true, std::memory_order_relaxed); }
}  // namespace detail

}  // namespace crease::rt
