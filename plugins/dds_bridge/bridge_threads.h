// Where a bridge's DDS calls run: never on a loop thread.
//   PublisherThread: the bridge's own thread, woken by the RT write phase after it put new values
//     into the publish links' channels (an atomic counter and a futex wake, no lock); writes them
//     with dds_write.
//   SubscriberListeners: listeners on the subscribe links' readers (data, liveliness, deadline,
//     lost, rejected, incompatible QoS, matched), run by Cyclone's threads of the bridge's domain
//     (its receive thread for data, as ddsperf does: one thread wake-up fewer per sample than a
//     waitset thread of our own, about 40 us at the median on this machine). Each takes the
//     samples and statuses of its link.
#pragma once

#include <dds/dds.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "links.h"

namespace crease::dds_bridge {

class PublisherThread {
 public:
  // `priority` 1..98: the thread runs SCHED_FIFO at it (when permitted; else a line on stderr
  // says why); 0: SCHED_OTHER.
  PublisherThread(std::vector<PublishLink*> links, int priority);
  ~PublisherThread();  // publishes nothing more; joins
  PublisherThread(const PublisherThread&) = delete;
  PublisherThread& operator=(const PublisherThread&) = delete;

  // RT-safe: new values wait in the links' channels. Never blocks; a futex wake only when the
  // thread sleeps.
  void wake_rt() noexcept {
    wake_.fetch_add(1, std::memory_order_release);
    wake_.notify_one();
  }

 private:
  void run(int priority);
  std::vector<PublishLink*> links_;
  std::atomic<std::uint32_t> wake_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

class SubscriberListeners {
 public:
  // Throws crease::Error when a listener cannot be set.
  explicit SubscriberListeners(std::vector<SubscribeLink*> links);
  ~SubscriberListeners();  // removes them; returns once no listener call is in progress
  SubscriberListeners(const SubscriberListeners&) = delete;
  SubscriberListeners& operator=(const SubscriberListeners&) = delete;

 private:
  std::vector<SubscribeLink*> links_;
};

}  // namespace crease::dds_bridge
