// crease-bench ports: ns per latest write/read and queue push/pop of a 256-byte payload,
// beside a mutex-protected slot measured in the same run.
#include <chrono>
#include <cstdio>
#include <mutex>
#include <thread>

#include "bench_registry.h"
#include "bench_util.h"
#include "rt/latest.h"
#include "rt/queue.h"

namespace {
struct Payload {
  std::uint64_t words[32];  // 256 bytes
};

template <class F>
double ns_per_op(std::uint64_t n, F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  for (std::uint64_t i = 0; i < n; ++i) f(i);
  const auto t1 = std::chrono::steady_clock::now();
  return std::chrono::duration<double, std::nano>(t1 - t0).count() / double(n);
}

// The alternative: a slot behind a mutex (what a first version of a port usually is).
struct MutexSlot {
  std::mutex mu;
  Payload value{};
  std::uint64_t seq = 0;
  void write(const Payload& p) {
    std::lock_guard lock(mu);
    value = p;
    ++seq;
  }
  std::uint64_t read(Payload& out) {
    std::lock_guard lock(mu);
    out = value;
    return seq;
  }
};

int run(int argc, char** argv) {
  const auto n = static_cast<std::uint64_t>(crease::bench::arg_double(argc, argv, "--ops", 5e6));
  Payload p{};
  Payload out{};
  volatile std::uint64_t sink = 0;

  crease::rt::LatestChannel latest(sizeof(Payload));
  crease::rt::QueueChannel queue(sizeof(Payload), 1024);
  MutexSlot slot;

  // Uncontended: the cost an RT thread pays per operation.
  const double latest_write = ns_per_op(n, [&](std::uint64_t i) { p.words[0] = i; latest.write(&p, std::int64_t(i)); });
  std::uint64_t seen = 0;
  const double latest_read = ns_per_op(n, [&](std::uint64_t i) {
    latest.write(&p, std::int64_t(i));  // keep it new so every read copies
    sink = sink + latest.read(&out, seen).seq;
  }) - latest_write;
  const double queue_pushpop = ns_per_op(n, [&](std::uint64_t) {
    (void)queue.try_push(&p);
    (void)queue.try_pop(&out);
  });
  const double mutex_write = ns_per_op(n, [&](std::uint64_t i) { p.words[0] = i; slot.write(p); });
  const double mutex_read = ns_per_op(n, [&](std::uint64_t) { sink = sink + slot.read(out); });

  // Contended: a reader thread hammers the port while the writer writes.
  std::atomic<bool> stop{false};
  std::thread reader([&] {
    Payload o{};
    std::uint64_t last = 0;
    while (!stop.load(std::memory_order_relaxed)) last = latest.read(&o, last).seq;
  });
  const double latest_write_contended = ns_per_op(n, [&](std::uint64_t i) { latest.write(&p, std::int64_t(i)); });
  stop = true;
  reader.join();
  stop = false;
  std::thread reader2([&] {
    Payload o{};
    while (!stop.load(std::memory_order_relaxed)) (void)slot.read(o);
  });
  const double mutex_write_contended = ns_per_op(n, [&](std::uint64_t) { slot.write(p); });
  stop = true;
  reader2.join();

  std::printf("ports: 256-byte payload, %llu operations each (ns per operation)\n", (unsigned long long)n);
  std::printf("  %-34s %10s %10s %8s\n", "", "crease", "mutex", "ratio");
  std::printf("  %-34s %10.1f %10.1f %8.2f\n", "latest write", latest_write, mutex_write, latest_write / mutex_write);
  std::printf("  %-34s %10.1f %10.1f %8.2f\n", "latest read (new value)", latest_read, mutex_read, latest_read / mutex_read);
  std::printf("  %-34s %10.1f %10.1f %8.2f\n", "latest write, reader spinning", latest_write_contended,
              mutex_write_contended, latest_write_contended / mutex_write_contended);
  std::printf("  %-34s %10.1f\n", "queue push + pop", queue_pushpop);
  std::printf("ports: latest_write_ns=%.1f latest_read_ns=%.1f queue_push_pop_ns=%.1f mutex_write_ns=%.1f "
              "mutex_read_ns=%.1f contended_write_ns=%.1f contended_mutex_write_ns=%.1f\n",
              latest_write, latest_read, queue_pushpop, mutex_write, mutex_read, latest_write_contended,
              mutex_write_contended);
  return sink == 42 ? 1 : 0;
}
}  // namespace

CREASE_BENCH(ports, "ns per latest write/read and queue push/pop (256 bytes) vs a mutex slot", run);
