// A bridge's Cyclone DDS participant, on this process's domain of its id (non-RT).
//
// The domain comes from a CycloneDDS XML configuration (interfaces, peers, multicast, ports);
// the first bridge of a process to use a domain id creates the domain from its file, and later
// ones must name a file with the same content (Cyclone runs one configuration per domain per
// process). The domain is deleted with its last participant.
#pragma once

#include <dds/dds.h>

#include <stdexcept>
#include <string>

namespace crease::dds_bridge {

// A configuration error about one parameter (`key`); the plugin adds file, line and path.
class ParamError : public std::runtime_error {
 public:
  ParamError(std::string key, const std::string& reason) : std::runtime_error(reason), key_(std::move(key)) {}
  [[nodiscard]] const std::string& key() const noexcept { return key_; }

 private:
  std::string key_;
};

class Participant {
 public:
  static constexpr int kMaxDomainId = 230;  // DDS: ports of higher ids overflow 16 bits

  // Reads `xml_path` and joins domain `domain_id`, or when it is -1 the id the XML names
  // (<Domain Id="N">; 0 when it says "any" or nothing). Throws ParamError naming "dds_config"
  // (unreadable file, no <Domain>, refused by Cyclone: with Cyclone's reason, another file already
  // configures this domain) or "domain" (differs from the XML's id).
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
