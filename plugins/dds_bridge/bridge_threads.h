// The bridge's own non-RT threads: every DDS call of a bridge runs on one of them (or, for
// discovery and the network, on Cyclone's threads), never on a loop thread.
//   PublisherThread: woken by the RT write phase after it put new values into publish links'
//     channels (an atomic counter and a futex wake, no lock); writes them with dds_write.
//   SubscriberThread: waits on a waitset of the subscribe links' readers (data, liveliness,
//     deadline, lost, rejected, incompatible QoS, matched) and a guard condition to stop.
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
  explicit PublisherThread(std::vector<PublishLink*> links);
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
  void run();
  std::vector<PublishLink*> links_;
  std::atomic<std::uint32_t> wake_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

class SubscriberThread {
 public:
  // Throws ParamError when the waitset cannot be made.
  SubscriberThread(dds_entity_t participant, std::vector<SubscribeLink*> links);
  ~SubscriberThread();  // takes nothing more; joins
  SubscriberThread(const SubscriberThread&) = delete;
  SubscriberThread& operator=(const SubscriberThread&) = delete;

 private:
  void run();
  std::vector<SubscribeLink*> links_;
  dds_entity_t waitset_ = 0;
  dds_entity_t stop_guard_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace crease::dds_bridge
