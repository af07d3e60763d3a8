// A fixed team of our own threads that runs n independent tasks (one per camera) together with
// the calling thread: the alternative to cv::parallel_for_ (TBB's pool) for the per-camera
// detection. Every thread is a std::thread of ours, synchronised with std::atomic wait/notify
// only, so ThreadSanitizer sees all of it (with cv::setNumThreads(1), OpenCV's own loops inside
// a task run inline too). Not RT code (tasks run OpenCV), but run() itself allocates nothing.
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <thread>
#include <vector>

namespace crease::vision {

class TaskTeam {
 public:
  // `helpers` threads besides the caller (0: run() does every task on the caller); >= 0
  // (CREASE_DEMAND).
  explicit TaskTeam(int helpers);
  ~TaskTeam();
  TaskTeam(const TaskTeam&) = delete;
  TaskTeam& operator=(const TaskTeam&) = delete;

  // Calls task(k) once for every k in [0, n), on the caller and the helpers, and returns when
  // all are done (their effects visible to the caller). One run at a time (one caller thread).
  // If tasks throw, the first exception seen is rethrown here after every task finished.
  template <class Task>
  void run(int n, Task& task) {
    run_erased(n, const_cast<void*>(static_cast<const void*>(&task)),
               [](void* t, int k) { (*static_cast<Task*>(t))(k); });
  }
  [[nodiscard]] int helpers() const noexcept { return static_cast<int>(threads_.size()); }

 private:
  void run_erased(int n, void* task, void (*call)(void*, int));
  void helper_loop(std::size_t slot);
  void work(std::exception_ptr& error) noexcept;  // claims tasks until none is left

  // Set by run() before the generation is bumped; helpers read them after seeing it, and are
  // all parked again before run() returns.
  void* task_ = nullptr;
  void (*call_)(void*, int) = nullptr;
  int n_ = 0;
  std::vector<std::exception_ptr> errors_;  // one per helper, read by run() once all parked
  std::atomic<int> next_{0};                 // next task index to claim
  std::atomic<int> parked_{0};               // helpers done with the current generation
  std::atomic<std::uint64_t> generation_{0};
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
};

}  // namespace crease::vision
