#include "topic_qos.h"

#include <cctype>

namespace crease::dds_bridge {

std::string dds_topic_name(const Params& entry, std::size_t max_length) {
  std::string name = entry.get<std::string>("topic");
  if (!name.empty() && name.front() == '/') name.erase(0, 1);
  const auto bad = [&](const std::string& why) { entry.fail("topic", "'" + name + "' " + why); };
  if (name.empty()) bad("is empty");
  bool token_start = true;
  for (const char ch : name) {
    const auto c = static_cast<unsigned char>(ch);
    if (ch == '/') {
      if (token_start) bad("has an empty token (ROS 2 names are tokens separated by single '/')");
      token_start = true;
      continue;
    }
    if (!(std::isalnum(c) || ch == '_')) bad("has a character other than letters, digits, '_' and '/'");
    if (token_start && std::isdigit(c)) bad("has a token starting with a digit");
    token_start = false;
  }
  if (token_start) bad("ends with '/'");
  const std::string dds = "rt/" + name;
  if (dds.size() > max_length) bad("is too long (at most " + std::to_string(max_length - 3) + " characters)");
  return dds;
}

TopicQos parse_qos(const Params& entry, bool events) {
  TopicQos q;
  const std::string rel = entry.get<std::string>("reliability", "reliable");
  if (rel == "reliable") {
    q.reliable = true;
  } else if (rel == "best_effort") {
    q.reliable = false;
  } else {
    entry.fail("reliability", "expected reliable or best_effort, got '" + rel + "'");
  }
  if (events && !q.reliable)
    entry.fail("reliability", "a queue topic is reliable (each event delivered once, none lost while the peer is up)");
  if (events && entry.has("deadline_ms"))
    entry.fail("deadline_ms", "a queue topic has no deadline (its events come when they come)");
  q.keep_all = events && !entry.has("depth");
  q.depth = entry.get_in_range<int>("depth", 1, 1, 1000);
  q.deadline_ns = static_cast<std::int64_t>(entry.get_in_range<double>("deadline_ms", 0.0, 0.0, 3.6e6) * 1e6);
  q.liveliness_ns = static_cast<std::int64_t>(entry.get_in_range<double>("liveliness_ms", 1000.0, 0.0, 3.6e6) * 1e6);
  return q;
}

QosPtr make_qos(const TopicQos& q) {
  QosPtr qos(dds_create_qos());
  if (q.keep_all) {
    dds_qset_history(qos.get(), DDS_HISTORY_KEEP_ALL, 0);
  } else {
    dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, q.depth);
  }
  dds_qset_reliability(qos.get(), q.reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_MSECS(100));
  dds_qset_durability(qos.get(), DDS_DURABILITY_VOLATILE);
  dds_qset_deadline(qos.get(), q.deadline_ns > 0 ? q.deadline_ns : DDS_INFINITY);
  dds_qset_liveliness(qos.get(), DDS_LIVELINESS_AUTOMATIC, q.liveliness_ns > 0 ? q.liveliness_ns : DDS_INFINITY);
  return qos;
}

}  // namespace crease::dds_bridge
