#include "core/control/request_parser.h"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/control/protocol.h"

namespace crease::control {
namespace {

using json = nlohmann::json;

ParsedRequest failure(json id, const char* code, std::string message) {
  ParsedRequest p;
  p.id = std::move(id);
  p.error_code = code;
  p.error_message = std::move(message);
  return p;
}

bool has_nul(const std::string& s) { return s.find('\0') != std::string::npos; }

// "" when V is of type T, else why not.
std::string type_error(const json& v, ArgType t) {
  switch (t) {
    case ArgType::string:
      if (!v.is_string() || v.get_ref<const std::string&>().empty()) return "must be a non-empty string";
      if (has_nul(v.get_ref<const std::string&>())) {
        return "contains a NUL character: '" + printable(v.get_ref<const std::string&>()) + "'";
      }
      return "";
    case ArgType::integer:
      if (!v.is_number_integer()) return "must be an integer (a JSON number)";
      if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX)) {
        return "must be an integer of 64 bits";
      }
      return "";
    case ArgType::number:
      if (!v.is_number()) return "must be a number (a JSON number, not a string)";
      if (v.is_number_float() && !std::isfinite(v.get<double>())) return "must be a finite number";
      return "";
    case ArgType::object:
      return v.is_object() ? "" : "must be an object";
    case ArgType::string_map:
      if (!v.is_object()) return "must be an object of strings";
      for (const auto& [k, s] : v.items()) {
        if (!s.is_string() || s.get_ref<const std::string&>().empty() || has_nul(s.get_ref<const std::string&>())) {
          return "must be an object of non-empty strings without NUL ('" + printable(k) + "' is not)";
        }
      }
      return "";
  }
  return "has an unknown type";
}

// The parser's events (nlohmann's SAX interface) into the request's DOM, with every object's
// keys checked as they are read: the first key an object has twice is noted, and from there
// on nothing is built (the request is refused whatever follows; the parse goes on only to
// tell a text that is not JSON at all). One map insertion per key: no callback per event, no
// second set of keys.
class StrictDom {
 public:
  explicit StrictDom(json& root) : root_(root) {}

  bool null() { return put(json(nullptr)), true; }
  bool boolean(bool v) { return put(json(v)), true; }
  bool number_integer(json::number_integer_t v) { return put(json(v)), true; }
  bool number_unsigned(json::number_unsigned_t v) { return put(json(v)), true; }
  bool number_float(json::number_float_t v, const json::string_t&) { return put(json(v)), true; }
  bool string(json::string_t& v) { return put(json(std::move(v))), true; }
  bool binary(json::binary_t& v) { return put(json(std::move(v))), true; }  // not in JSON text
  bool start_object(std::size_t) { return open(json::value_t::object); }
  bool start_array(std::size_t) { return open(json::value_t::array); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool key(json::string_t& k) {
    if (duplicate_) return true;
    auto& object = open_.back()->get_ref<json::object_t&>();
    const auto [it, inserted] = object.try_emplace(std::move(k));  // K stays when it is there
    if (inserted) {
      slot_ = &it->second;
    } else {
      duplicate_ = true;
      duplicate_key_ = k;
    }
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) { return false; }

  [[nodiscard]] bool duplicate() const noexcept { return duplicate_; }
  [[nodiscard]] const std::string& duplicate_key() const noexcept { return duplicate_key_; }

 private:
  // V as the next value: the root, the next item of the open array, or the value of the key
  // just read. nullptr once a duplicate stopped the building.
  json* put(json&& v) {
    if (duplicate_) return nullptr;
    if (open_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    json& top = *open_.back();
    if (top.is_array()) {
      auto& items = top.get_ref<json::array_t&>();
      items.push_back(std::move(v));
      return &items.back();  // valid while open: its array takes no item until it is closed
    }
    *slot_ = std::move(v);
    return slot_;
  }
  bool open(json::value_t t) {
    if (json* c = put(json(t))) open_.push_back(c);
    return true;
  }
  bool close() {
    if (!duplicate_) open_.pop_back();
    return true;
  }

  json& root_;
  std::vector<json*> open_;  // the containers being read, outermost first
  json* slot_ = nullptr;     // the value of the key just read
  bool duplicate_ = false;
  std::string duplicate_key_;
};

}  // namespace

ParsedRequest parse_request(std::string_view line) {
  json req;
  StrictDom dom(req);
  if (!json::sax_parse(line.begin(), line.end(), &dom)) return failure(nullptr, kErrorMalformed, "request is not JSON");
  if (dom.duplicate()) {
    return failure(nullptr, kErrorMalformed, "request has the key '" + printable(dom.duplicate_key()) + "' twice");
  }
  if (!req.is_object()) return failure(nullptr, kErrorMalformed, "request is not a JSON object");
  json id = req.contains("id") ? req["id"] : json(nullptr);
  const auto cmd = req.find("cmd");
  if (cmd == req.end() || !cmd->is_string()) return failure(std::move(id), kErrorMalformed, "request has no string 'cmd'");
  const std::string& name = cmd->get_ref<const std::string&>();
  const CommandSpec* spec = find_command_spec(name);
  if (spec == nullptr) return failure(std::move(id), kErrorUnknownCommand, "unknown command '" + printable(name) + "'");
  for (const auto& [key, value] : req.items()) {
    if (key == "id" || key == "cmd") continue;
    const ArgSpec* arg = nullptr;
    for (const ArgSpec& a : spec->args) {
      if (key == a.name) arg = &a;
    }
    if (arg == nullptr) {
      return failure(std::move(id), kErrorBadArgument, "'" + name + "' takes no argument '" + printable(key) + "'");
    }
    if (value.is_null()) continue;  // the same as absent; the handler says when it is needed
    const std::string why = type_error(value, arg->type);
    if (!why.empty()) {
      return failure(std::move(id), kErrorBadArgument, "'" + name + "': argument '" + key + "' " + why);
    }
  }
  ParsedRequest p;
  p.id = std::move(id);
  p.request = std::move(req);
  return p;
}

}  // namespace crease::control
