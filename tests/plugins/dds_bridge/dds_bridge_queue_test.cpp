// dds_bridge's queue ports (queue_links.h) between two hosts of one process: the sheet model's
// edits (sheet_crease, sheet_memorize) pushed on one host arrive on the other's queue ports once
// each, in order, and nothing more on later cycles; an unbridged queue port's events arrive
// nowhere (the failing variant); a queue topic is stale only while no publisher is alive; a full
// port drops and counts what does not fit, the loop unblocked; bad events from a raw Cyclone
// writer are counted and dropped; the RT part allocates nothing.
// The test thread is the one producer of the publishing host's queue ports and the one consumer
// of the subscribing host's (no plugin binds the other end).
#include <dds/dds.h>
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "SheetCreaseEvent.h"
#include "SheetMemorizeEvent.h"
#include "bridge_fixture.h"
#include "core/port_types/sheet_state.h"
#include "raw_writer.h"
#include "rogue_sheet_edit.h"
#include "rt/alloc_guard.h"

using namespace crease;
using crease::test::BridgeHost;
using crease::test::bridge_params;
using crease::test::eventually;
using crease::test::raw_writer;
using crease::test::test_domain;
using crease::test::test_topic;

namespace {
// A publishes the queue ports sheet_crease and sheet_memorize (only memorize: `crease` false).
void add_publisher(BridgeHost& a, const std::string& tag, bool crease = true) {
  const std::string memorize = "{port: sheet_memorize, topic: " + test_topic(tag + "/memorize") + ", type: sheet_memorize}";
  a.add("bridge", "dds_bridge", 10,
        bridge_params("publish: [" +
                      (crease ? "{port: sheet_crease, topic: " + test_topic(tag + "/crease") + ", type: sheet_crease}, "
                              : std::string()) +
                      memorize + "]"));
}
void add_subscriber(BridgeHost& b, const std::string& tag) {
  b.add("bridge", "dds_bridge", 0,
        bridge_params("subscribe: [{topic: " + test_topic(tag + "/crease") +
                      ", port: sheet_crease, type: sheet_crease}, {topic: " + test_topic(tag + "/memorize") +
                      ", port: sheet_memorize, type: sheet_memorize}]"));
}
rt::QueueChannel& queue(BridgeHost& h, const std::string& port) {
  rt::QueueChannel* q = h.host.ports().find_queue(port);
  REQUIRE(q != nullptr);
  return *q;
}
SheetCreaseEvent crease_event(int i) {
  SheetCreaseEvent e;
  e.timestamp_ns = 1000 + i;
  e.op = SheetCreaseEvent::Op::add;
  e.id = i;
  e.a_mm[0] = static_cast<float>(i);
  e.a_mm[1] = 2.0f * static_cast<float>(i);
  e.b_mm[0] = 0.5f;
  e.b_mm[1] = -static_cast<float>(i);
  return e;
}
SheetMemorizeEvent memorize_event(int i) {
  SheetMemorizeEvent e;
  e.timestamp_ns = 5000 + i;
  e.whole_sheet = i % 2 == 0;
  e.min_mm[0] = static_cast<float>(i);
  e.max_mm[1] = 3.0f * static_cast<float>(i);
  return e;
}
template <class T>
std::vector<T> drain(rt::QueueChannel& q) {
  std::vector<T> out;
  T e;
  while (q.try_pop(&e)) out.push_back(e);
  return out;
}
// Both hosts' links matched: events pushed now are heard (volatile topics keep nothing for a
// subscriber that comes later).
bool matched(const BridgeHost& a, const BridgeHost& b, std::uint32_t topics) {
  const BridgeStats sa = a.stats("bridge"), sb = b.stats("bridge");
  for (std::uint32_t i = 0; i < topics; ++i)
    if (sa.topics[i].matched != 1) return false;
  return sb.topics[0].matched == 1 && sb.topics[1].matched == 1 && sb.stale == 0;
}
}  // namespace

TEST_CASE("queue ports: every event arrives once, in order, and nothing on later cycles; the RT part allocates nothing") {
  BridgeHost b;
  add_subscriber(b, "edits");
  // Before any publisher: a queue topic is stale (no publisher alive), so the bridge degraded.
  b.host.start();
  REQUIRE(eventually([&] { return b.stats("bridge").stale == 2 && b.degraded("bridge") > 0; }));
  auto a = std::make_unique<BridgeHost>();
  add_publisher(*a, "edits");
  a->host.start();
  REQUIRE(eventually([&] { return matched(*a, b, 2); }));
  const BridgeStats fresh = b.stats("bridge");
  CHECK(fresh.topics[0].queue == 1);
  CHECK(fresh.topics[0].stale == 0);  // a live publisher and no event yet: not stale
  CHECK(drain<SheetCreaseEvent>(queue(b, "sheet_crease")).empty());

  REQUIRE(rt::alloc_hooks_installed());
  const auto allocations = rt::rt_allocation_count();
  const std::uint64_t degraded = b.degraded("bridge");
  rt::QueueChannel& crease_in = queue(*a, "sheet_crease");
  rt::QueueChannel& memorize_in = queue(*a, "sheet_memorize");
  rt::QueueChannel& crease_out = queue(b, "sheet_crease");
  rt::QueueChannel& memorize_out = queue(b, "sheet_memorize");

  // Three bursts: many events in one cycle, then a few, then one alone.
  constexpr int kN = 150;
  std::vector<SheetCreaseEvent> creases;
  std::vector<SheetMemorizeEvent> memorizes;
  int next = 0;
  for (const int burst : {120, 29, 1}) {
    for (int i = 0; i < burst; ++i, ++next) {
      REQUIRE(crease_in.try_push(&(creases.emplace_back(crease_event(next)))));
      REQUIRE(memorize_in.try_push(&(memorizes.emplace_back(memorize_event(next)))));
    }
    REQUIRE(eventually([&] { return crease_out.pushed() == static_cast<std::uint64_t>(next) &&
                                    memorize_out.pushed() == static_cast<std::uint64_t>(next); }));
  }
  REQUIRE(next == kN);
  const std::vector<SheetCreaseEvent> got_c = drain<SheetCreaseEvent>(crease_out);
  const std::vector<SheetMemorizeEvent> got_m = drain<SheetMemorizeEvent>(memorize_out);
  REQUIRE(got_c.size() == kN);
  REQUIRE(got_m.size() == kN);
  for (int i = 0; i < kN; ++i) {
    CHECK(got_c[i].timestamp_ns == creases[i].timestamp_ns);
    CHECK(got_c[i].op == creases[i].op);
    CHECK(got_c[i].id == creases[i].id);
    CHECK(std::memcmp(got_c[i].a_mm, creases[i].a_mm, sizeof(creases[i].a_mm)) == 0);
    CHECK(std::memcmp(got_c[i].b_mm, creases[i].b_mm, sizeof(creases[i].b_mm)) == 0);
    CHECK(got_m[i].timestamp_ns == memorizes[i].timestamp_ns);
    CHECK(got_m[i].whole_sheet == memorizes[i].whole_sheet);
    CHECK(got_m[i].min_mm[0] == memorizes[i].min_mm[0]);
    CHECK(got_m[i].max_mm[1] == memorizes[i].max_mm[1]);
  }

  // Later cycles with nothing new give nothing: no event is repeated.
  const std::uint64_t cycles = b.updates("bridge");
  REQUIRE(eventually([&] { return b.updates("bridge") > cycles + 300; }));
  CHECK(drain<SheetCreaseEvent>(crease_out).empty());
  CHECK(drain<SheetMemorizeEvent>(memorize_out).empty());
  CHECK(crease_out.pushed() == kN);
  CHECK(memorize_out.pushed() == kN);
  CHECK(rt::rt_allocation_count() == allocations);
  CHECK(b.degraded("bridge") == degraded);  // a publisher alive all along

  REQUIRE(eventually([&] { return b.stats("bridge").topics[0].port_writes == kN; }));
  const BridgeStats sb = b.stats("bridge");
  for (int t = 0; t < 2; ++t) {
    CHECK(sb.topics[t].samples == kN);
    CHECK(sb.topics[t].port_writes == kN);
    CHECK(sb.topics[t].queue_full == 0);
    CHECK(sb.topics[t].malformed + sb.topics[t].undecodable + sb.topics[t].lost == 0);
  }
  const BridgeStats sa = a->stats("bridge");
  for (int t = 0; t < 2; ++t) {
    CHECK(sa.topics[t].queue == 1);
    CHECK(sa.topics[t].samples == kN);
    CHECK(sa.topics[t].lost == 0);
    CHECK(sa.topics[t].queue_full == 0);
  }

  // The publisher gone: stale (degraded) until one returns.
  a.reset();
  REQUIRE(eventually([&] { return b.stats("bridge").stale == 2; }));
  CHECK(b.stats("bridge").topics[0].liveliness_lost > 0);
  CHECK(drain<SheetCreaseEvent>(crease_out).empty());
  b.host.stop();
}

TEST_CASE("failing variant: a queue port the publishing bridge does not bridge delivers nothing") {
  BridgeHost a, b;
  // a's sheet_crease has a writer (this thread) but no bridge entry; sheet_memorize is bridged.
  rt::QueueChannel* crease_in = a.host.ports().bind_queue_writer(
      "sheet_crease", port_type_of<SheetCreaseEvent>(), "test", PortRegistry::kDefaultQueueCapacity);
  add_publisher(a, "unbridged", false);
  add_subscriber(b, "unbridged");
  a.host.start();
  b.host.start();
  REQUIRE(eventually([&] {
    const BridgeStats sa = a.stats("bridge"), sb = b.stats("bridge");
    return sa.topics[0].matched == 1 && sb.topics[1].matched == 1;
  }));
  constexpr int kN = 20;
  for (int i = 0; i < kN; ++i) {
    const SheetCreaseEvent c = crease_event(i);
    REQUIRE(crease_in->try_push(&c));
  }
  rt::QueueChannel& memorize_in = queue(a, "sheet_memorize");
  for (int i = 0; i < kN; ++i) {
    const SheetMemorizeEvent m = memorize_event(i);
    REQUIRE(memorize_in.try_push(&m));
  }
  REQUIRE(eventually([&] { return queue(b, "sheet_memorize").pushed() == kN; }));  // the bridged one works
  const std::uint64_t cycles = b.updates("bridge");
  REQUIRE(eventually([&] { return b.updates("bridge") > cycles + 300; }));
  CHECK(queue(b, "sheet_crease").pushed() == 0);
  CHECK(drain<SheetCreaseEvent>(queue(b, "sheet_crease")).empty());
  CHECK(b.stats("bridge").topics[0].samples == 0);
  CHECK(b.stats("bridge").topics[0].stale == 1);  // no publisher of it at all
  CHECK(crease_in->size_approx() == kN);          // never taken
  b.host.stop();
  a.host.stop();
}

TEST_CASE("a reader that falls behind: the full port drops the newest events and counts them, the loop runs on") {
  BridgeHost b;
  add_subscriber(b, "full");
  b.host.start();
  BridgeHost a;
  add_publisher(a, "full");
  a.host.start();
  REQUIRE(eventually([&] { return matched(a, b, 2); }));
  rt::QueueChannel& in = queue(a, "sheet_crease");
  rt::QueueChannel& out = queue(b, "sheet_crease");
  const std::size_t capacity = out.capacity();
  // Nobody pops b's port: its first `capacity` events stay, the 44 after them are dropped.
  int next = 0;
  for (const std::size_t burst : {capacity - 56, std::size_t{100}}) {
    for (std::size_t i = 0; i < burst; ++i, ++next) {
      const SheetCreaseEvent e = crease_event(next);
      REQUIRE(in.try_push(&e));
    }
    REQUIRE(eventually([&] { return b.stats("bridge").topics[0].samples == static_cast<std::uint64_t>(next); }));
  }
  REQUIRE(eventually([&] { return b.stats("bridge").topics[0].queue_full == 44; }));
  const std::uint64_t cycles = b.updates("bridge");
  REQUIRE(eventually([&] { return b.updates("bridge") > cycles + 100; }));  // not blocked
  CHECK(b.stats("bridge").topics[0].port_writes == capacity);
  CHECK(b.stats("bridge").topics[0].queue_full == 44);
  const std::vector<SheetCreaseEvent> got = drain<SheetCreaseEvent>(out);
  REQUIRE(got.size() == capacity);
  CHECK(got.front().id == 0);
  CHECK(got.back().id == static_cast<std::int32_t>(capacity) - 1);
  b.host.stop();
  a.host.stop();
}

TEST_CASE("bad events from the network are counted and dropped, never pushed into the queue port") {
  BridgeHost b;
  add_subscriber(b, "bad");
  b.host.start();
  const dds_entity_t pp = dds_create_participant(static_cast<dds_domainid_t>(test_domain()), nullptr, nullptr);
  REQUIRE(pp > 0);
  const auto writer = [&](const dds_topic_descriptor_t* type, const std::string& topic) {
    return raw_writer(pp, type, test_topic(topic), true);
  };
  const dds_entity_t cw = writer(&crease_msgs_msg_dds__SheetCreaseEvent__desc, "bad/crease");
  const dds_entity_t mw = writer(&crease_msgs_msg_dds__SheetMemorizeEvent__desc, "bad/memorize");

  // Creases: good add, a NaN end point, an unknown op, a remove of id 40 (ids are 0..31), good remove.
  crease_msgs_msg_dds__SheetCreaseEvent_ c{};
  c.timestamp_ns = 1;
  c.a_mm[0] = 10;
  REQUIRE(dds_write(cw, &c) == 0);
  c.timestamp_ns = 2;
  c.b_mm[1] = std::nanf("");
  REQUIRE(dds_write(cw, &c) == 0);
  c.b_mm[1] = 0;
  c.op = 7;
  REQUIRE(dds_write(cw, &c) == 0);
  c.op = 1;
  c.id = 40;
  REQUIRE(dds_write(cw, &c) == 0);
  c.timestamp_ns = 3;
  c.id = 3;
  REQUIRE(dds_write(cw, &c) == 0);
  // Memorize: an infinite corner, then a good one.
  crease_msgs_msg_dds__SheetMemorizeEvent_ m{};
  m.timestamp_ns = 4;
  m.max_mm[0] = INFINITY;
  REQUIRE(dds_write(mw, &m) == 0);
  m.max_mm[0] = 5;
  m.whole_sheet = true;
  REQUIRE(dds_write(mw, &m) == 0);

  REQUIRE(eventually([&] {
    const BridgeStats s = b.stats("bridge");
    return s.topics[0].malformed == 3 && s.topics[0].port_writes == 2 && s.topics[1].malformed == 1 &&
           s.topics[1].port_writes == 1;
  }));
  const std::vector<SheetCreaseEvent> got = drain<SheetCreaseEvent>(queue(b, "sheet_crease"));
  REQUIRE(got.size() == 2);
  CHECK(got[0].timestamp_ns == 1);
  CHECK(got[0].op == SheetCreaseEvent::Op::add);
  CHECK(got[0].a_mm[0] == 10.0f);
  CHECK(got[1].timestamp_ns == 3);
  CHECK(got[1].op == SheetCreaseEvent::Op::remove);
  CHECK(got[1].id == 3);
  const std::vector<SheetMemorizeEvent> got_m = drain<SheetMemorizeEvent>(queue(b, "sheet_memorize"));
  REQUIRE(got_m.size() == 1);
  CHECK(got_m[0].timestamp_ns == 4);
  CHECK(got_m[0].whole_sheet);

  // An event of the wrong size (a look-alike type without the crease line): Cyclone refuses to
  // decode it; counted, not pushed.
  const dds_topic_descriptor_t& r = rogue_msgs_msg_dds__SheetCreaseEvent__desc;
  const dds_topic_descriptor_t look_alike{r.m_size,  r.m_align, r.m_flagset, r.m_nkeys,
                                          "crease_msgs::msg::dds_::SheetCreaseEvent_", r.m_keys, r.m_nops, r.m_ops,
                                          r.m_meta,  r.type_information, r.type_mapping,
                                          r.restrict_data_representation};
  const dds_entity_t pp2 = dds_create_participant(static_cast<dds_domainid_t>(test_domain()), nullptr, nullptr);
  REQUIRE(pp2 > 0);
  const dds_entity_t rw = raw_writer(pp2, &look_alike, test_topic("bad/crease"), true);
  rogue_msgs_msg_dds__SheetCreaseEvent_ short_one{9, 0};
  REQUIRE(dds_write(rw, &short_one) == 0);
  REQUIRE(eventually([&] { return b.stats("bridge").topics[0].undecodable == 1; }));
  const std::uint64_t cycles = b.updates("bridge");
  REQUIRE(eventually([&] { return b.updates("bridge") > cycles + 100; }));
  CHECK(drain<SheetCreaseEvent>(queue(b, "sheet_crease")).empty());
  CHECK(b.stats("bridge").topics[0].port_writes == 2);
  CHECK(b.state("bridge") == RunState::active);
  dds_delete(pp2);
  dds_delete(pp);
  b.host.stop();
}
