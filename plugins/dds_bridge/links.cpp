#include "links.h"

#include <algorithm>
#include <cstring>

#include "core/errors.h"
#include "participant.h"

namespace crease::dds_bridge {

Endpoint::Endpoint(dds_entity_t participant, const dds_topic_descriptor_t* type, const std::string& topic,
                   const TopicQos& qos, bool writer) {
  const QosPtr q = make_qos(qos);
  topic_ = dds_create_topic(participant, type, topic.c_str(), q.get(), nullptr);
  if (topic_ < 0)
    throw crease::Error("DDS refused topic " + topic + " of type " + type->m_typename + ": " +
                        dds_strretcode(topic_));
  endpoint_ = writer ? dds_create_writer(participant, topic_, q.get(), nullptr)
                     : dds_create_reader(participant, topic_, q.get(), nullptr);
  if (endpoint_ < 0) {
    const std::string why = dds_strretcode(endpoint_);
    dds_delete(topic_);
    throw crease::Error(std::string("DDS refused a ") + (writer ? "writer" : "reader") + " of " +
                        topic + " with this QoS: " + why);
  }
}

Endpoint::~Endpoint() {
  dds_delete(endpoint_);
  dds_delete(topic_);
}

void Link::stats_rt(BridgeTopicStats& out) const noexcept {
  const auto get = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  const LinkCounters& c = counters_;
  out.direction = direction_;
  out.queue = c.events ? 1 : 0;
  out.stale = direction_ == BridgeTopicStats::subscribe && c.stale.load(std::memory_order_acquire) ? 1 : 0;
  out.matched = static_cast<std::uint16_t>(std::min<std::uint32_t>(c.matched.load(std::memory_order_relaxed), 0xffff));
  out.samples = get(c.samples);
  out.port_writes = port_writes_;
  out.overwritten = get(c.overwritten);
  out.lost = get(c.lost);
  out.rejected = get(c.rejected);
  out.malformed = get(c.malformed);
  out.oversized = get(c.oversized);
  out.undecodable = get(c.undecodable);
  out.deadline_missed = get(c.deadline_missed);
  out.liveliness_lost = get(c.liveliness_lost);
  out.incompatible_qos = get(c.incompatible_qos);
  out.queue_full = get(c.queue_full);
}

namespace {
void add(std::atomic<std::uint64_t>& a, std::int64_t n) {
  if (n > 0) a.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
}
}  // namespace

void on_status(LinkCounters& c, const dds_liveliness_changed_status_t& s) {
  add(c.liveliness_lost, -static_cast<std::int64_t>(s.alive_count_change));
  if (s.alive_count == 0) {
    c.stale.store(true, std::memory_order_release);
  } else if (c.events) {
    c.stale.store(false, std::memory_order_release);  // a queue topic: a live publisher is all it needs
  }
}
void on_status(LinkCounters& c, const dds_requested_deadline_missed_status_t& s) {
  add(c.deadline_missed, s.total_count_change);
  c.stale.store(true, std::memory_order_release);
}
void on_status(LinkCounters& c, const dds_sample_lost_status_t& s) { add(c.lost, s.total_count_change); }
void on_status(LinkCounters& c, const dds_sample_rejected_status_t& s) { add(c.rejected, s.total_count_change); }
void on_status(LinkCounters& c, const dds_requested_incompatible_qos_status_t& s) {
  add(c.incompatible_qos, s.total_count_change);
}
void on_status(LinkCounters& c, const dds_subscription_matched_status_t& s) {
  c.matched.store(s.current_count, std::memory_order_relaxed);
}

void catch_up_statuses(dds_entity_t reader, LinkCounters& c) {
  dds_liveliness_changed_status_t l;
  if (dds_get_liveliness_changed_status(reader, &l) == 0) on_status(c, l);
  dds_requested_deadline_missed_status_t d;
  if (dds_get_requested_deadline_missed_status(reader, &d) == 0 && d.total_count_change > 0) on_status(c, d);
  dds_sample_lost_status_t lost;
  if (dds_get_sample_lost_status(reader, &lost) == 0) on_status(c, lost);
  dds_sample_rejected_status_t r;
  if (dds_get_sample_rejected_status(reader, &r) == 0) on_status(c, r);
  dds_requested_incompatible_qos_status_t q;
  if (dds_get_requested_incompatible_qos_status(reader, &q) == 0) on_status(c, q);
  dds_subscription_matched_status_t m;
  if (dds_get_subscription_matched_status(reader, &m) == 0) on_status(c, m);
}

void take_writer_statuses(dds_entity_t writer, LinkCounters& c) {
  dds_publication_matched_status_t m;
  if (dds_get_publication_matched_status(writer, &m) == 0) c.matched.store(m.current_count, std::memory_order_relaxed);
  dds_offered_incompatible_qos_status_t q;
  if (dds_get_offered_incompatible_qos_status(writer, &q) == 0 && q.total_count_change > 0)
    c.incompatible_qos.fetch_add(static_cast<std::uint64_t>(q.total_count_change), std::memory_order_relaxed);
}

void listen_to_writer(dds_entity_t writer, LinkCounters& c) {
  dds_listener_t* l = dds_create_listener(&c);
  dds_lset_publication_matched(l, [](dds_entity_t, const dds_publication_matched_status_t s, void* arg) {
    static_cast<LinkCounters*>(arg)->matched.store(s.current_count, std::memory_order_relaxed);
  });
  dds_lset_offered_incompatible_qos(l, [](dds_entity_t, const dds_offered_incompatible_qos_status_t s, void* arg) {
    if (s.total_count_change > 0)
      static_cast<LinkCounters*>(arg)->incompatible_qos.fetch_add(static_cast<std::uint64_t>(s.total_count_change),
                                                                  std::memory_order_relaxed);
  });
  const dds_return_t rc = dds_set_listener(writer, l);
  dds_delete_listener(l);
  if (rc < 0) throw crease::Error(std::string("cannot listen to a writer: ") + dds_strretcode(rc));
  take_writer_statuses(writer, c);  // what came before the listener was set
}

}  // namespace crease::dds_bridge
