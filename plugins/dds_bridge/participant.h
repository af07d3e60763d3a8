// A bridge's Cyclone DDS participant, on this process's domain of its id (non-RT).
//
// The domain comes from a CycloneDDS XML configuration (interfaces, peers, multicast, ports);
// the first bridge of a process to use a domain id creates the domain from its file, and later
// ones must name a file with the same content (Cyclone runs one configuration per domain per
// process). The domain is deleted with its last participant.
#pragma once

#include <dds/dds.h>

#include <string>

namespace crease::dds_bridge {

// Errors are crease::Error naming the file and the reason (core/assert.h: a failure of the
// environment at configure time); the plugin attributes them to the parameter that named the
// file (Params::fail: file, line and key).
class Participant {
 public:
  static constexpr int kMaxDomainId = 230;  // DDS: ports of higher ids overflow 16 bits

  // The domain id the CycloneDDS XML at `xml_path` names (<Domain Id="N">), -1 when it says
  // "any" or nothing. Throws crease::Error: unreadable file, no <Domain>, not an id.
  [[nodiscard]] static int configured_domain(const std::string& xml_path);

  // Reads `xml_path` and joins domain `domain_id` (0..kMaxDomainId; the caller checked it
  // against configured_domain). Throws crease::Error: unreadable file, refused by Cyclone (with
  // Cyclone's reason), another file already configures this domain in this process.
  Participant(const std::string& xml_path, int domain_id);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  [[nodiscard]] dds_entity_t handle() const noexcept { return participant_; }
  [[nodiscard]] dds_domainid_t domain() const noexcept { return domain_; }

 private:
  dds_domainid_t domain_ = 0;
  dds_entity_t participant_ = 0;
};

}  // namespace crease::dds_bridge
