#include "plugins/robot_model/urdf_reader.h"

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include <fstream>
#include <mutex>
#include <sstream>

#include "core/errors.h"

namespace crease::robot {
namespace {

// Collects what urdfdom says while it parses; installed for the duration of one parse.
class CapturedLog final : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors.push_back(text);
    else if (level == console_bridge::CONSOLE_BRIDGE_LOG_WARN) warnings.push_back(text);
  }
  std::vector<std::string> errors, warnings;
};

class CaptureScope {
 public:
  explicit CaptureScope(CapturedLog& log) : lock_(mutex()), level_(console_bridge::getLogLevel()) {
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_WARN);
    console_bridge::useOutputHandler(&log);
  }
  ~CaptureScope() {
    console_bridge::restorePreviousOutputHandler();
    console_bridge::setLogLevel(level_);
  }
  CaptureScope(const CaptureScope&) = delete;
  CaptureScope& operator=(const CaptureScope&) = delete;

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  console_bridge::LogLevel level_;
};

void collect_children(const tinyxml2::XMLElement& parent, std::vector<UrdfSource::Child>& out) {
  for (const auto* c = parent.FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) {
    UrdfSource::Child child;
    child.tag = c->Name();
    child.line = c->GetLineNum();
    for (const auto* a = c->FirstAttribute(); a != nullptr; a = a->Next()) {
      child.attribute_values.emplace_back(a->Value());
    }
    out.push_back(std::move(child));
    collect_children(*c, out);
  }
}

UrdfSource index_source(const std::string& text, const std::string& file) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS) {
    throw ConfigError(file + ":" + std::to_string(doc.ErrorLineNum()) + ": XML: " + doc.ErrorStr());
  }
  const tinyxml2::XMLElement* robot = doc.RootElement();
  if (robot == nullptr || std::string_view(robot->Name()) != "robot") {
    const int line = robot ? robot->GetLineNum() : 1;
    throw ConfigError(file + ":" + std::to_string(line) + ": the root element must be <robot>");
  }
  std::vector<UrdfSource::Element> elements;
  for (const auto* e = robot->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    const std::string_view tag = e->Name();
    if (tag != "link" && tag != "joint") continue;
    UrdfSource::Element el;
    el.kind = std::string(tag);
    const char* name = e->Attribute("name");
    el.name = name ? name : "";
    el.line = e->GetLineNum();
    collect_children(*e, el.children);
    elements.push_back(std::move(el));
  }
  return UrdfSource(file, std::move(elements));
}

// Names urdfdom quotes in its messages: [name], 'name' and (value).
std::vector<std::string> quoted_tokens(const std::string& msg) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < msg.size(); ++i) {
    char close = 0;
    if (msg[i] == '[') close = ']';
    else if (msg[i] == '(') close = ')';
    else if (msg[i] == '\'') close = '\'';
    if (close == 0) continue;
    const std::size_t end = msg.find(close, i + 1);
    if (end == std::string::npos) break;
    if (end > i + 1) out.push_back(msg.substr(i + 1, end - i - 1));
    i = end;
  }
  return out;
}

bool value_holds(const std::string& value, const std::string& token) {
  if (value == token) return true;
  std::istringstream words(value);
  std::string w;
  while (words >> w) {
    if (w == token) return true;
  }
  return false;
}

// The located message for a file urdfdom refused.
std::string locate(const UrdfSource& src, const CapturedLog& log, const std::string& thrown) {
  std::vector<std::string> msgs = log.errors.empty() ? log.warnings : log.errors;
  if (!thrown.empty()) msgs.push_back(thrown);
  std::string reason;
  for (const auto& m : msgs) reason += (reason.empty() ? "" : "; ") + m;
  if (reason.empty()) reason = "urdfdom refused the file";

  std::vector<std::string> tokens;
  for (const auto& m : msgs) {
    for (auto& t : quoted_tokens(m)) tokens.push_back(std::move(t));
  }
  const bool duplicate = reason.find("not unique") != std::string::npos;
  const UrdfSource::Element* element = nullptr;
  for (const auto& t : tokens) {
    for (const auto& e : src.elements()) {
      if (e.name == t && (element == nullptr || (duplicate && element->name == t))) element = &e;
    }
    if (element != nullptr) break;
  }
  if (element == nullptr) return src.file() + ": " + reason;
  for (const auto& t : tokens) {
    if (t == element->name) continue;
    for (const auto& c : element->children) {
      for (const auto& v : c.attribute_values) {
        if (value_holds(v, t)) {
          return src.file() + ":" + std::to_string(c.line) + ": " + element->kind + " '" +
                 element->name + "' <" + c.tag + ">: " + reason;
        }
      }
    }
  }
  return src.file() + ":" + std::to_string(element->line) + ": " + element->kind + " '" +
         element->name + "': " + reason;
}

}  // namespace

const UrdfSource::Element* UrdfSource::find(std::string_view kind, std::string_view name) const noexcept {
  for (const auto& e : elements_) {
    if (e.kind == kind && e.name == name) return &e;
  }
  return nullptr;
}

std::string UrdfSource::where(std::string_view kind, std::string_view name) const {
  const Element* e = find(kind, name);
  const std::string what = std::string(kind) + " '" + std::string(name) + "'";
  if (e == nullptr) return file_ + ": " + what;
  return file_ + ":" + std::to_string(e->line) + ": " + what;
}

void UrdfSource::fail(std::string_view kind, std::string_view name, const std::string& reason) const {
  throw ConfigError(where(kind, name) + ": " + reason);
}

void UrdfSource::fail_at_child(std::string_view kind, std::string_view name, std::string_view tag,
                               int index, const std::string& reason) const {
  if (const Element* e = find(kind, name)) {
    int seen = 0;
    for (const auto& c : e->children) {
      if (c.tag == tag && seen++ == index) {
        throw ConfigError(file_ + ":" + std::to_string(c.line) + ": " + std::string(kind) + " '" +
                          std::string(name) + "' <" + std::string(tag) + ">: " + reason);
      }
    }
  }
  fail(kind, name, reason);
}

UrdfDocument read_urdf_text(const std::string& text, const std::string& file) {
  UrdfDocument doc;
  doc.source = index_source(text, file);
  CapturedLog log;
  std::string thrown;
  {
    const CaptureScope scope(log);
    try {
      doc.model = urdf::parseURDF(text);
    } catch (const std::exception& e) {
      thrown = e.what();
    }
  }
  // urdfdom 3.0 logs some errors (a bad number in a <collision>, say) and still returns a
  // model without the broken part: any error is a refusal.
  if (!doc.model || !log.errors.empty()) throw ConfigError(locate(doc.source, log, thrown));
  return doc;
}

UrdfDocument read_urdf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ": cannot open the URDF");
  std::ostringstream text;
  text << in.rdbuf();
  return read_urdf_text(text.str(), path);
}

}  // namespace crease::robot
