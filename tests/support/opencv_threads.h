// For the tests of our threads next to OpenCV (label `concurrency`, run under ThreadSanitizer):
// the camera workers, the vision worker, the task team. Link tests/support/tsan_third_party.cpp
// with them (its suppressions are for third-party code only).
#pragma once

#include <chrono>
#include <filesystem>
#include <iterator>
#include <opencv2/core/utility.hpp>
#include <thread>

namespace crease::testing {

// OpenCV runs its parallel loops inline on the calling thread, so it starts no TBB workers and
// every thread in the process is one of ours. TBB's workers run uninstrumented code that
// synchronises through futexes TSan cannot see; buffers they touch (memcpy, free) would show as
// races in our code. With this, TSan sees every access and every hand-over. Process-wide; call
// it first. Under TSan it also starts the runtime's background thread now (it starts with the
// first thread created), so that process_threads() counts from here on are exact.
inline void own_threads_only() {
  cv::setNumThreads(1);
#ifdef CREASE_SANITIZER_THREAD
  std::thread([] {}).join();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the kernel reaps it
#endif
}

// Threads of this process now (/proc/self/task) but the sanitizer runtime's own (TSan runs one
// background thread, started by own_threads_only()): checks that no thread but ours exists.
inline long process_threads() {
#ifdef CREASE_SANITIZER_THREAD
  constexpr long kRuntimeThreads = 1;
#else
  constexpr long kRuntimeThreads = 0;
#endif
  const std::filesystem::directory_iterator it("/proc/self/task");
  return std::distance(begin(it), end(it)) - kRuntimeThreads;
}

}  // namespace crease::testing
