// The links of a bridge for queue ports (events: sheet_edit_mirror.h gives Dds<T>), on the
// bases of links.h. Each event is one DDS sample of a reliable topic (KEEP_ALL by default,
// topic_qos.h): delivered once, in order, none lost while the peer is up.
//
// Each link owns a lock-free rt::QueueChannel (SPSC, capacity kChannelCapacity) between the RT
// side and its non-RT side, as the latest links own a LatestChannel:
//   publish:   RT write phase: every event of the port -> channel (take_rt);
//              publisher thread: channel -> dds_write, one sample per event, in order
//   subscribe: reader listener: dds_take -> checks -> channel (receive);
//              RT update: every event of the channel -> the port, in order
// A full queue on the way (the channel, or the port whose reader fell behind) drops the event
// and counts it (queue_full): never blocks the loop. A queue topic is stale only while no
// publisher of it is alive (liveliness): with one alive and nothing sent there is simply no
// event. Events are delivered while stale (an event that came is one; there is no "old" event).
#pragma once

#include <dds/dds.h>

#include <memory>
#include <mutex>
#include <string>

#include "core/port.h"
#include "core/port_binder.h"
#include "core/port_registry.h"
#include "dds_log.h"
#include "links.h"
#include "rt/clock.h"
#include "rt/queue.h"
#include "sample_check.h"
#include "topic_qos.h"

namespace crease::dds_bridge {

// Events in flight between a link's RT side and its non-RT side (the port queues' capacity).
inline constexpr std::size_t kChannelCapacity = PortRegistry::kDefaultQueueCapacity;

template <class T, class D>
class QueuePublishLinkT final : public PublishLink {
 public:
  QueuePublishLinkT(PortBinder& ports, const std::string& port, dds_entity_t participant, const std::string& topic,
                    const TopicQos& qos)
      : PublishLink(topic, true),
        in_(ports.queue_input<T>(port)),
        channel_(sizeof(T), kChannelCapacity),
        endpoint_(participant, D::descriptor(), topic, qos, true),
        sample_(std::make_unique<typename D::C>()),
        scratch_(std::make_unique<typename D::Scratch>()) {
    listen_to_writer(endpoint_.handle(), counters());
  }

  bool take_rt() noexcept override {
    bool any = false;
    while (in_.try_pop(rt_event_)) {
      any = true;
      if (!channel_.try_push(&rt_event_)) counters().queue_full.fetch_add(1, std::memory_order_relaxed);
    }
    return any;
  }

  void publish() override {
    while (channel_.try_pop(&event_)) {
      // No subscriber matched: nobody hears it (volatile topics keep nothing for late joiners).
      const bool heard = counters().matched.load(std::memory_order_relaxed) > 0;
      D::to_dds(event_, *sample_, *scratch_);
      if (dds_write(endpoint_.handle(), sample_.get()) < 0 || !heard) {
        counters().lost.fetch_add(1, std::memory_order_relaxed);
      } else {
        counters().samples.fetch_add(1, std::memory_order_relaxed);
      }
    }
  }

 private:
  QueueInput<T> in_;           // RT side
  T rt_event_{};               // RT side: the event being moved
  rt::QueueChannel channel_;   // RT -> publisher thread
  T event_{};                  // publisher thread: the event being written
  Endpoint endpoint_;
  std::unique_ptr<typename D::C> sample_;
  std::unique_ptr<typename D::Scratch> scratch_;
};

template <class T, class D>
class QueueSubscribeLinkT final : public SubscribeLink {
 public:
  QueueSubscribeLinkT(PortBinder& ports, const std::string& port, dds_entity_t participant, const std::string& topic,
                      const TopicQos& qos)
      : SubscribeLink(topic, true),
        out_(ports.queue_output<T>(port)),
        channel_(sizeof(T), kChannelCapacity),
        endpoint_(participant, D::descriptor(), topic, qos, false) {
    DdsLog::instance().watch(topic, D::descriptor()->m_typename, &counters().undecodable);
  }
  ~QueueSubscribeLinkT() override { DdsLog::instance().unwatch(&counters().undecodable); }

  [[nodiscard]] dds_entity_t reader() const noexcept override { return endpoint_.handle(); }

  void receive() override {
    const std::lock_guard lock(receiving_);
    take_samples<D, 16>(endpoint_.handle(), staging_, counters(), [this] {
      counters().samples.fetch_add(1, std::memory_order_relaxed);
      if (!channel_.try_push(&staging_)) counters().queue_full.fetch_add(1, std::memory_order_relaxed);
    });
  }

  bool give_rt() noexcept override {
    while (channel_.try_pop(&rt_event_)) {
      if (out_.try_push(rt_event_)) {
        ++port_writes_;
      } else {
        counters().queue_full.fetch_add(1, std::memory_order_relaxed);
      }
    }
    return !counters().stale.load(std::memory_order_acquire);
  }

 private:
  QueueOutput<T> out_;         // RT side
  T rt_event_{};               // RT side: the event being moved
  rt::QueueChannel channel_;   // listener -> RT
  Endpoint endpoint_;
  std::mutex receiving_;       // listener calls: one at a time (never taken by the RT side)
  T staging_{};                // listener: the event being checked
};

}  // namespace crease::dds_bridge
