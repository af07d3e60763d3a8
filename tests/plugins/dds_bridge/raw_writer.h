// A raw Cyclone writer for the dds_bridge tests that play a peer sending bad samples.
#pragma once

#include <dds/dds.h>
#include <doctest/doctest.h>

#include <string>

#include "bridge_fixture.h"

namespace crease::test {

// A writer of TYPE on "rt/" + TOPIC in participant PP, with QoS the bridge's default reader
// accepts (reliable, automatic liveliness within its 1000 ms lease; KEEP_ALL history when asked,
// as a queue topic's writer), returned once it has matched the bridge's reader.
inline dds_entity_t raw_writer(dds_entity_t pp, const dds_topic_descriptor_t* type, const std::string& topic,
                               bool keep_all = false) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  if (keep_all) dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
  dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, DDS_MSECS(500));
  const dds_entity_t t = dds_create_topic(pp, type, ("rt/" + topic).c_str(), q, nullptr);
  REQUIRE(t > 0);
  const dds_entity_t w = dds_create_writer(pp, t, q, nullptr);
  dds_delete_qos(q);
  REQUIRE(w > 0);
  REQUIRE(eventually([&] {
    dds_publication_matched_status_t m;
    return dds_get_publication_matched_status(w, &m) == 0 && m.current_count == 1;
  }));
  return w;
}

}  // namespace crease::test
