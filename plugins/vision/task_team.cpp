#include "plugins/vision/task_team.h"

#include "core/assert.h"

namespace crease::vision {

TaskTeam::TaskTeam(int helpers) {
  CREASE_DEMAND(helpers >= 0, "TaskTeam: negative number of helper threads");
  errors_.resize(static_cast<std::size_t>(helpers));
  threads_.reserve(static_cast<std::size_t>(helpers));
  for (std::size_t i = 0; i < static_cast<std::size_t>(helpers); ++i)
    threads_.emplace_back([this, i] { helper_loop(i); });
}

TaskTeam::~TaskTeam() {
  stop_.store(true, std::memory_order_release);
  generation_.fetch_add(1, std::memory_order_acq_rel);
  generation_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void TaskTeam::work(std::exception_ptr& error) noexcept {
  for (int k = next_.fetch_add(1, std::memory_order_relaxed); k < n_;
       k = next_.fetch_add(1, std::memory_order_relaxed)) {
    try {
      call_(task_, k);
    } catch (...) {
      if (!error) error = std::current_exception();
    }
  }
}

void TaskTeam::helper_loop(std::size_t slot) {
  std::uint64_t seen = 0;
  while (true) {
    generation_.wait(seen, std::memory_order_acquire);
    seen = generation_.load(std::memory_order_acquire);
    if (stop_.load(std::memory_order_acquire)) return;
    work(errors_[slot]);
    // Publishes this helper's task effects (and its error slot) to run().
    parked_.fetch_add(1, std::memory_order_acq_rel);
    parked_.notify_all();
  }
}

void TaskTeam::run_erased(int n, void* task, void (*call)(void*, int)) {
  task_ = task;
  call_ = call;
  n_ = n;
  next_.store(0, std::memory_order_relaxed);
  parked_.store(0, std::memory_order_relaxed);
  const int helpers = static_cast<int>(threads_.size());
  if (helpers > 0) {
    generation_.fetch_add(1, std::memory_order_release);  // publishes the fields above
    generation_.notify_all();
  }
  std::exception_ptr error;
  work(error);
  // Every helper takes part in every generation, so none reads task_/n_/next_ after this.
  for (int p = parked_.load(std::memory_order_acquire); p != helpers;
       p = parked_.load(std::memory_order_acquire))
    parked_.wait(p, std::memory_order_acquire);
  for (std::exception_ptr& e : errors_) {
    if (!error && e) error = e;
    e = nullptr;
  }
  task_ = nullptr;
  if (error) std::rethrow_exception(error);
}

}  // namespace crease::vision
