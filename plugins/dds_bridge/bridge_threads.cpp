#include "bridge_threads.h"

#include <pthread.h>

#include "participant.h"

namespace crease::dds_bridge {

namespace {
constexpr std::uint32_t kReaderStatuses = DDS_DATA_AVAILABLE_STATUS | DDS_LIVELINESS_CHANGED_STATUS |
                                          DDS_REQUESTED_DEADLINE_MISSED_STATUS | DDS_SAMPLE_LOST_STATUS |
                                          DDS_SAMPLE_REJECTED_STATUS | DDS_REQUESTED_INCOMPATIBLE_QOS_STATUS |
                                          DDS_SUBSCRIPTION_MATCHED_STATUS;
}  // namespace

PublisherThread::PublisherThread(std::vector<PublishLink*> links) : links_(std::move(links)) {
  thread_ = std::thread([this] { run(); });
  pthread_setname_np(thread_.native_handle(), "dds-publish");
}

PublisherThread::~PublisherThread() {
  stop_.store(true, std::memory_order_release);
  wake_.fetch_add(1, std::memory_order_release);
  wake_.notify_all();
  thread_.join();
}

void PublisherThread::run() {
  for (;;) {
    // Read the counter before the channels: a wake during the pass makes wait() return at once.
    const std::uint32_t seen = wake_.load(std::memory_order_acquire);
    if (stop_.load(std::memory_order_acquire)) return;
    for (PublishLink* l : links_) l->publish();
    wake_.wait(seen, std::memory_order_acquire);
  }
}

SubscriberThread::SubscriberThread(dds_entity_t participant, std::vector<SubscribeLink*> links)
    : links_(std::move(links)) {
  waitset_ = dds_create_waitset(participant);
  stop_guard_ = dds_create_guardcondition(participant);
  if (waitset_ < 0 || stop_guard_ < 0 || dds_waitset_attach(waitset_, stop_guard_, 0) < 0)
    throw ParamError("subscribe", "no DDS waitset for the subscriber thread");
  for (std::size_t i = 0; i < links_.size(); ++i) {
    const dds_entity_t r = links_[i]->reader();
    if (dds_set_status_mask(r, kReaderStatuses) < 0 ||
        dds_waitset_attach(waitset_, r, static_cast<dds_attach_t>(i + 1)) < 0)
      throw ParamError("subscribe", "cannot wait on the reader of " + links_[i]->topic());
  }
  thread_ = std::thread([this] { run(); });
  pthread_setname_np(thread_.native_handle(), "dds-subscribe");
}

SubscriberThread::~SubscriberThread() {
  stop_.store(true, std::memory_order_release);
  dds_set_guardcondition(stop_guard_, true);
  thread_.join();
  dds_delete(waitset_);
  dds_delete(stop_guard_);
}

void SubscriberThread::run() {
  std::vector<dds_attach_t> triggered(links_.size() + 1);
  // Samples may have come before the waitset was attached: look once.
  for (SubscribeLink* l : links_) l->receive();
  while (!stop_.load(std::memory_order_acquire)) {
    const dds_return_t n = dds_waitset_wait(waitset_, triggered.data(), triggered.size(), DDS_INFINITY);
    for (dds_return_t i = 0; i < n; ++i) {
      const dds_attach_t a = triggered[static_cast<std::size_t>(i)];
      if (a >= 1 && static_cast<std::size_t>(a) <= links_.size()) links_[static_cast<std::size_t>(a) - 1]->receive();
    }
  }
}

}  // namespace crease::dds_bridge
