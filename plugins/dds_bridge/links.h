// The links of a bridge: one per configured entry, between a local latest port and a DDS
// endpoint, typed by the port payload T (keypoints_mirror.h, hand_mirror.h, arm_mirror.h,
// sheet_mirror.h give Dds<T>; joint_state_view.h a publish-only view). Queue ports (events)
// have their own links on the same bases (queue_links.h).
//
// Each link owns a lock-free rt::LatestChannel between the RT side and its non-RT side:
//   publish:   RT write phase: port -> channel (take_rt); publisher thread: channel -> dds_write
//   subscribe: reader listener: dds_take -> checks -> channel (receive); RT update: channel -> port
// Counters are atomics the non-RT side adds to and the RT side reads (stats_rt), never locks.
#pragma once

#include <dds/dds.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "core/port.h"
#include "core/port_binder.h"
#include "core/port_types/bridge_stats.h"
#include "dds_log.h"
#include "rt/clock.h"
#include "rt/latest.h"
#include "sample_check.h"
#include "topic_qos.h"

namespace crease::dds_bridge {

// Counted by the non-RT side (relaxed: plain totals), read by the RT side.
struct LinkCounters {
  std::atomic<std::uint64_t> samples{0}, lost{0}, rejected{0}, malformed{0}, oversized{0}, undecodable{0},
      deadline_missed{0}, liveliness_lost{0}, incompatible_qos{0}, overwritten{0}, queue_full{0};
  std::atomic<std::uint32_t> matched{0};
  std::atomic<bool> stale{true};  // subscribe only: no fresh data (never heard, lost or late)
  // A queue topic (set before any thread sees the link): stale only while no publisher is alive.
  bool events = false;
};

// The DDS topic and endpoint of a link (non-RT; deleted with the link).
class Endpoint {
 public:
  Endpoint(dds_entity_t participant, const dds_topic_descriptor_t* type, const std::string& topic,
           const TopicQos& qos, bool writer);
  ~Endpoint();
  Endpoint(const Endpoint&) = delete;
  Endpoint& operator=(const Endpoint&) = delete;
  [[nodiscard]] dds_entity_t handle() const noexcept { return endpoint_; }

 private:
  dds_entity_t topic_ = 0;
  dds_entity_t endpoint_ = 0;
};

class Link {
 public:
  Link(std::string topic, BridgeTopicStats::Direction direction, bool queue = false)
      : topic_(std::move(topic)), direction_(direction) {
    counters_.events = queue;
  }
  virtual ~Link() = default;
  Link(const Link&) = delete;
  Link& operator=(const Link&) = delete;

  [[nodiscard]] const std::string& topic() const noexcept { return topic_; }
  [[nodiscard]] LinkCounters& counters() noexcept { return counters_; }
  [[nodiscard]] const LinkCounters& counters() const noexcept { return counters_; }
  // RT-safe: the counters as the stats port shows them (topic name filled in at configure).
  void stats_rt(BridgeTopicStats& out) const noexcept;

 protected:
  std::uint64_t port_writes_ = 0;  // RT side only (subscribe)

 private:
  std::string topic_;
  BridgeTopicStats::Direction direction_;
  LinkCounters counters_;
};

class PublishLink : public Link {
 public:
  explicit PublishLink(std::string topic, bool queue = false) : Link(std::move(topic), BridgeTopicStats::publish, queue) {}
  // RT (write phase): a new port value (a queue: every event) into the channel; true when there was one.
  virtual bool take_rt() noexcept = 0;
  // Publisher thread: the channel's value to DDS when it is new to this side.
  virtual void publish() = 0;
};

class SubscribeLink : public Link {
 public:
  explicit SubscribeLink(std::string topic, bool queue = false)
      : Link(std::move(topic), BridgeTopicStats::subscribe, queue) {}
  // The reader's data listener (a Cyclone thread): takes the samples. One call at a time (a
  // lock: several Cyclone threads may call). The status listeners call on_status (links.cpp).
  virtual void receive() = 0;
  [[nodiscard]] virtual dds_entity_t reader() const noexcept = 0;
  // RT (update): the newest sample into the port unless stale (a queue: every event that came);
  // true when the port is fresh.
  virtual bool give_rt() noexcept = 0;
};

// A reader's status listeners (Cyclone threads): Cyclone hands each its status (and resets it).
// Liveliness with no writer alive, or a missed deadline, makes the link stale.
void on_status(LinkCounters& c, const dds_liveliness_changed_status_t& s);
void on_status(LinkCounters& c, const dds_requested_deadline_missed_status_t& s);
void on_status(LinkCounters& c, const dds_sample_lost_status_t& s);
void on_status(LinkCounters& c, const dds_sample_rejected_status_t& s);
void on_status(LinkCounters& c, const dds_requested_incompatible_qos_status_t& s);
void on_status(LinkCounters& c, const dds_subscription_matched_status_t& s);
// The same for every status of `reader` that changed before its listener was set.
void catch_up_statuses(dds_entity_t reader, LinkCounters& c);
// Publisher thread: the writer's matched and incompatible-QoS statuses into `c`.
void take_writer_statuses(dds_entity_t writer, LinkCounters& c);

// A reader's data listener: takes every sample waiting at READER, kBatch at a time, checks each
// into STAGING (D::from_dds), counts the malformed and oversized ones in C, and calls ACCEPT for
// each good one (which counts it and hands it on); Cyclone's loans are returned.
template <class D, int kBatch, class Staging, class Accept>
void take_samples(dds_entity_t reader, Staging& staging, LinkCounters& c, Accept accept) {
  void* samples[kBatch] = {};
  dds_sample_info_t infos[kBatch];
  for (;;) {
    const dds_return_t n = dds_take(reader, samples, infos, kBatch, kBatch);
    if (n <= 0) break;
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      switch (D::from_dds(*static_cast<const typename D::C*>(samples[i]), staging)) {
        case SampleCheck::ok:
          accept();
          break;
        case SampleCheck::malformed:
          c.malformed.fetch_add(1, std::memory_order_relaxed);
          break;
        case SampleCheck::oversized:
          c.oversized.fetch_add(1, std::memory_order_relaxed);
          break;
      }
    }
    dds_return_loan(reader, samples, n);
    if (n < kBatch) break;
  }
}
// The same kept current by listeners on `writer` (Cyclone's threads), for a link that writes
// rarely (queue topics); `c` must outlive the writer. Throws crease::Error when refused.
void listen_to_writer(dds_entity_t writer, LinkCounters& c);

template <class T, class D>
class PublishLinkT final : public PublishLink {
 public:
  // D: the wire form (Dds<T>, or a view such as JointStateView<T>); `scratch` its storage.
  PublishLinkT(PortBinder& ports, const std::string& port, dds_entity_t participant, const std::string& topic,
               const TopicQos& qos, std::unique_ptr<typename D::Scratch> scratch = std::make_unique<typename D::Scratch>())
      : PublishLink(topic),
        in_(ports.latest_input<T>(port)),
        channel_(sizeof(T)),
        reader_(&channel_),
        endpoint_(participant, D::descriptor(), topic, qos, true),
        sample_(std::make_unique<typename D::C>()),
        scratch_(std::move(scratch)) {}

  bool take_rt() noexcept override {
    const rt::ReadInfo info = in_.poll();
    if (!info.is_new()) return false;
    channel_.write(&in_.value(), info.stamp_ns);
    return true;
  }

  void publish() override {
    const std::uint64_t before = reader_.held().seq;
    const rt::ReadInfo info = reader_.poll();
    if (!info.is_new()) return;
    if (before != 0 && info.seq > before + 1) counters().overwritten.fetch_add(info.seq - before - 1, std::memory_order_relaxed);
    D::to_dds(reader_.value(), *sample_, *scratch_);
    if (dds_write(endpoint_.handle(), sample_.get()) < 0) {
      counters().lost.fetch_add(1, std::memory_order_relaxed);
    } else {
      counters().samples.fetch_add(1, std::memory_order_relaxed);
    }
    if (++since_status_ >= kStatusEvery || info.seq == 1) {
      since_status_ = 0;
      take_writer_statuses(endpoint_.handle(), counters());
    }
  }

 private:
  static constexpr int kStatusEvery = 64;  // samples between two looks at the writer's statuses
  LatestInput<T> in_;           // RT side
  rt::LatestChannel channel_;   // RT -> publisher thread
  rt::LatestReader<T> reader_;  // publisher thread
  Endpoint endpoint_;
  std::unique_ptr<typename D::C> sample_;         // publisher thread: the sample being written
  std::unique_ptr<typename D::Scratch> scratch_;  // and the storage its sequences point into
  int since_status_ = 0;
};

template <class T, class D>
class SubscribeLinkT final : public SubscribeLink {
 public:
  SubscribeLinkT(PortBinder& ports, const std::string& port, dds_entity_t participant, const std::string& topic,
                 const TopicQos& qos)
      : SubscribeLink(topic),
        out_(ports.latest_output<T>(port, *std::make_unique<T>())),  // safe value T{} (off the stack: a sheet is 164 kB)
        channel_(sizeof(T)),
        reader_(&channel_),
        endpoint_(participant, D::descriptor(), topic, qos, false),
        staging_(std::make_unique<T>()) {
    DdsLog::instance().watch(topic, D::descriptor()->m_typename, &counters().undecodable);
  }
  ~SubscribeLinkT() override { DdsLog::instance().unwatch(&counters().undecodable); }

  [[nodiscard]] dds_entity_t reader() const noexcept override { return endpoint_.handle(); }

  void receive() override {
    const std::lock_guard lock(receiving_);
    take_samples<D, 8>(endpoint_.handle(), *staging_, counters(), [this] {
      channel_.write(staging_.get(), rt::now_ns());  // stamped with its arrival here
      counters().samples.fetch_add(1, std::memory_order_relaxed);
      counters().stale.store(false, std::memory_order_release);  // after the value is in
    });
  }

  bool give_rt() noexcept override {
    const std::uint64_t before = reader_.held().seq;
    const rt::ReadInfo info = reader_.poll();
    if (info.is_new() && before != 0 && info.seq > before + 1)
      counters().overwritten.fetch_add(info.seq - before - 1, std::memory_order_relaxed);
    // A value that came before the topic went stale is never written as new after it.
    if (counters().stale.load(std::memory_order_acquire)) return false;
    if (reader_.held().seq > written_seq_) {
      out_.write(reader_.value(), reader_.held().stamp_ns);
      written_seq_ = reader_.held().seq;
      ++port_writes_;
    }
    return reader_.has_value();
  }

 private:
  LatestOutput<T> out_;         // RT side
  rt::LatestChannel channel_;   // listener -> RT
  rt::LatestReader<T> reader_;  // RT side
  std::uint64_t written_seq_ = 0;
  Endpoint endpoint_;
  std::mutex receiving_;        // listener calls: one at a time (never taken by the RT side)
  std::unique_ptr<T> staging_;  // listener: the sample being checked
};

}  // namespace crease::dds_bridge
