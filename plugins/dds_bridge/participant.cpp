#include "participant.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <sstream>

#include "core/errors.h"
#include "dds_log.h"

namespace crease::dds_bridge {

namespace {

struct DomainEntry {
  dds_entity_t entity = 0;
  std::string xml;   // the configuration it was created from
  std::string path;  // and the file it came from
  int users = 0;
};

std::mutex g_mu;
std::map<dds_domainid_t, DomainEntry>& domains() {
  static std::map<dds_domainid_t, DomainEntry> d;
  return d;
}

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw crease::Error("cannot read " + path + ": " + std::strerror(errno));
  std::ostringstream s;
  s << f.rdbuf();
  if (f.bad()) throw crease::Error("cannot read " + path);
  return s.str();
}

// The id a <Domain Id="…"> element names: -1 for "any" or no attribute; throws without <Domain>.
int xml_domain_id(const std::string& xml, const std::string& path) {
  static const std::regex domain_tag(R"(<\s*Domain(\s[^>]*)?>)");
  static const std::regex id_attr(R"(\bId\s*=\s*["']\s*([^"']*?)\s*["'])", std::regex::icase);
  std::smatch m;
  if (!std::regex_search(xml, m, domain_tag))
    throw crease::Error(path +
                        " has no <Domain> element (so nothing says which interfaces to use)");
  const std::string attrs = m[1].str();
  std::smatch id;
  if (!std::regex_search(attrs, id, id_attr) || id[1].str() == "any") return -1;
  const std::string v = id[1].str();
  if (v.empty() || v.find_first_not_of("0123456789") != std::string::npos || v.size() > 3 ||
      std::stoi(v) > Participant::kMaxDomainId)
    throw crease::Error(path + ": <Domain Id=\"" + v + "\"> is not a domain id 0.." +
                        std::to_string(Participant::kMaxDomainId) + " or \"any\"");
  return std::stoi(v);
}

}  // namespace

int Participant::configured_domain(const std::string& xml_path) {
  return xml_domain_id(read_file(xml_path), xml_path);
}

Participant::Participant(const std::string& xml_path, int domain_id) {
  const std::string xml = read_file(xml_path);
  domain_ = static_cast<dds_domainid_t>(domain_id);

  const std::lock_guard lock(g_mu);
  DomainEntry& e = domains()[domain_];
  if (e.users == 0) {
    DdsLog::instance().acquire();
    DdsLog::Capture capture;
    const dds_entity_t d = dds_create_domain(domain_, xml.c_str());
    if (d < 0) {
      DdsLog::instance().release();
      domains().erase(domain_);
      std::string why = capture.text();
      while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
      throw crease::Error("CycloneDDS refused " + xml_path + " for domain " +
                          std::to_string(domain_) + " (" + dds_strretcode(d) +
                          (why.empty() ? "" : ": " + why) + ")");
    }
    e = DomainEntry{d, xml, xml_path, 0};
  } else if (e.xml != xml) {
    throw crease::Error("domain " + std::to_string(domain_) +
                        " already runs in this process with " + e.path + ", which differs from " +
                        xml_path);
  }
  participant_ = dds_create_participant(domain_, nullptr, nullptr);
  if (participant_ < 0) {
    const std::string why = dds_strretcode(participant_);
    if (e.users == 0) {
      dds_delete(e.entity);
      domains().erase(domain_);
      DdsLog::instance().release();
    }
    throw crease::Error("no participant on domain " + std::to_string(domain_) + ": " + why);
  }
  ++e.users;
}

Participant::~Participant() {
  const std::lock_guard lock(g_mu);
  dds_delete(participant_);
  auto it = domains().find(domain_);
  if (it != domains().end() && --it->second.users == 0) {
    dds_delete(it->second.entity);
    domains().erase(it);
    DdsLog::instance().release();
  }
}

}  // namespace crease::dds_bridge
