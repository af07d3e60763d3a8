#include "bridge_threads.h"

#include <pthread.h>

#include <cstdio>

#include "core/errors.h"
#include "participant.h"
#include "rt/rt_setup.h"

namespace crease::dds_bridge {

namespace {
// On the thread itself: SCHED_FIFO at `priority` when it is > 0 (a refusal is reported, not fatal).
void set_priority(const char* name, int priority) {
  if (priority <= 0) return;
  crease::rt::ThreadSettings s;
  s.priority = priority;
  s.stack_prefault_bytes = 0;
  for (const auto& step : crease::rt::apply_thread_settings(name, s))
    if (!step.applied) std::fprintf(stderr, "dds_bridge: %s not applied: %s\n", step.what.c_str(), step.why.c_str());
}
// Sets the listener for status S: the link's counters take it (on_status).
template <class S, class Setter>
void set_status(dds_listener_t* l, Setter setter) {
  setter(l, [](dds_entity_t, const S status, void* arg) { on_status(static_cast<SubscribeLink*>(arg)->counters(), status); });
}
}  // namespace

PublisherThread::PublisherThread(std::vector<PublishLink*> links, int priority) : links_(std::move(links)) {
  thread_ = std::thread([this, priority] { run(priority); });
  pthread_setname_np(thread_.native_handle(), "dds-publish");
}

PublisherThread::~PublisherThread() {
  stop_.store(true, std::memory_order_release);
  wake_.fetch_add(1, std::memory_order_release);
  wake_.notify_all();
  thread_.join();
}

void PublisherThread::run(int priority) {
  set_priority("dds-publish", priority);
  for (;;) {
    // Read the counter before the channels: a wake during the pass makes wait() return at once.
    const std::uint32_t seen = wake_.load(std::memory_order_acquire);
    if (stop_.load(std::memory_order_acquire)) return;
    for (PublishLink* l : links_) l->publish();
    wake_.wait(seen, std::memory_order_acquire);
  }
}

SubscriberListeners::SubscriberListeners(std::vector<SubscribeLink*> links) : links_(std::move(links)) {
  for (SubscribeLink* link : links_) {
    dds_listener_t* l = dds_create_listener(link);
    const auto on_data = [](dds_entity_t, void* arg) { static_cast<SubscribeLink*>(arg)->receive(); };
    dds_lset_data_available(l, on_data);
    set_status<dds_liveliness_changed_status_t>(l, &dds_lset_liveliness_changed);
    set_status<dds_requested_deadline_missed_status_t>(l, &dds_lset_requested_deadline_missed);
    set_status<dds_sample_lost_status_t>(l, &dds_lset_sample_lost);
    set_status<dds_sample_rejected_status_t>(l, &dds_lset_sample_rejected);
    set_status<dds_requested_incompatible_qos_status_t>(l, &dds_lset_requested_incompatible_qos);
    set_status<dds_subscription_matched_status_t>(l, &dds_lset_subscription_matched);
    const dds_return_t rc = dds_set_listener(link->reader(), l);
    dds_delete_listener(l);
    if (rc < 0) throw crease::Error("cannot listen to the reader of " + link->topic());
    catch_up_statuses(link->reader(), link->counters());  // what came before the listener was set
    link->receive();
  }
}

SubscriberListeners::~SubscriberListeners() {
  for (SubscribeLink* link : links_) dds_set_listener(link->reader(), nullptr);
}

}  // namespace crease::dds_bridge
