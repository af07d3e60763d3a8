// Tests for core/control/request_parser.h: what reaches a handler is an object with a known
// command, no key twice, no argument outside the command's spec, every argument of its JSON
// type; every refusal's code, and messages that keep client text whole (NUL included).
#include "core/control/request_parser.h"

#include <doctest/doctest.h>

#include <string>

#include "core/control/protocol.h"

namespace ctl = crease::control;
using namespace std::string_literals;

namespace {
// "code: message" of the refusal, or "ok".
std::string outcome(const std::string& line) {
  const ctl::ParsedRequest p = ctl::parse_request(line);
  return p.ok() ? "ok" : p.error_code + ": " + p.error_message;
}
}  // namespace

TEST_CASE("a key twice, at any depth, is malformed: the last value never wins") {
  CHECK(outcome(R"({"cmd":"status","cmd":"stop"})") == "malformed: request has the key 'cmd' twice");
  CHECK(outcome(R"({"id":1,"cmd":"load","params":{"k":1,"k":2}})") == "malformed: request has the key 'k' twice");
  CHECK(outcome(R"({"cmd":"load","params":{"a":{"k":1}},"ports":{"k":"x"}})").rfind("malformed", 0) != 0);  // other objects
  CHECK(outcome(R"({"cmd":"load","params":[{"k":1},{"k":2}]})").rfind("malformed", 0) != 0);
  CHECK(ctl::parse_request(R"({"id":5,"cmd":"stop","id":6})").id.is_null());  // which id? none
  CHECK(outcome(R"({"cmd":"status"})") == "ok");
  CHECK(outcome("{\"cmd\":\"status\"") == "malformed: request is not JSON");
  CHECK(outcome("[1]") == "malformed: request is not a JSON object");
  CHECK(outcome(R"({"id":5})") == "malformed: request has no string 'cmd'");
  CHECK(ctl::parse_request(R"({"id":5})").id == 5);
  CHECK(outcome(R"({"cmd":"dance"})") == "unknown_command: unknown command 'dance'");
}

TEST_CASE("every argument is of its JSON type; no argument outside the command's") {
  CHECK(outcome(R"({"cmd":"load","instance":"a","library":"b","loop":"c","order":1,"ports":{"out":"x"}})") == "ok");
  CHECK(outcome(R"({"cmd":"load","instance":"a","ports":[1]})") ==
        "bad_argument: 'load': argument 'ports' must be an object of strings");
  CHECK(outcome(R"({"cmd":"load","ports":{"out":1}})") ==
        "bad_argument: 'load': argument 'ports' must be an object of non-empty strings without NUL ('out' is not)");
  CHECK(outcome(R"({"cmd":"load","order":"10"})") == "bad_argument: 'load': argument 'order' must be an integer (a JSON number)");
  CHECK(outcome(R"({"cmd":"load","order":1.5})") == "bad_argument: 'load': argument 'order' must be an integer (a JSON number)");
  CHECK(outcome(R"({"cmd":"load","order":18446744073709551615})") == "bad_argument: 'load': argument 'order' must be an integer of 64 bits");
  CHECK(outcome(R"({"cmd":"swap","params":"k=1"})") == "bad_argument: 'swap': argument 'params' must be an object");
  CHECK(outcome(R"({"cmd":"unload","instance":""})") == "bad_argument: 'unload': argument 'instance' must be a non-empty string");
  CHECK(outcome(R"({"cmd":"unload","instance":7})") == "bad_argument: 'unload': argument 'instance' must be a non-empty string");
  CHECK(outcome(R"({"cmd":"status","extra":7})") == "bad_argument: 'status' takes no argument 'extra'");
  CHECK(outcome(R"({"cmd":"unload","instance":null})") == "ok");  // null is absent: the handler asks for it
  // param set: numbers only as JSON numbers.
  const std::string set = R"({"cmd":"param","action":"set","instance":"c","key":"k","value":)";
  CHECK(outcome(set + "16}") == "ok");
  CHECK(outcome(set + "-2.5e-3}") == "ok");
  for (const char* bad : {R"("0x10")", R"("16")", "true", "[16]", "{}"}) {
    CAPTURE(bad);
    CHECK(outcome(set + bad + "}") == "bad_argument: 'param': argument 'value' must be a number (a JSON number, not a string)");
  }
  CHECK(outcome(set + "1e999}").rfind("malformed", 0) == 0);  // not a double: refused by the parser
}

TEST_CASE("a NUL inside a string is refused with the whole string in the message") {
  const std::string line = "{\"cmd\":\"unload\",\"instance\":\"counter\\u0000../../evil\"}";
  CHECK(outcome(line) == "bad_argument: 'unload': argument 'instance' contains a NUL character: 'counter\\u0000../../evil'");
  CHECK(outcome("{\"cmd\":\"dance\\u0000 and more\"}") == "unknown_command: unknown command 'dance\\u0000 and more'");
  CHECK(outcome("{\"cmd\":\"status\",\"a\\u0000b\":1}") == "bad_argument: 'status' takes no argument 'a\\u0000b'");
  CHECK(ctl::printable("a\0b\n\x7f" "c"s) == "a\\u0000b\\u000a\\u007fc");
  CHECK(ctl::printable("naïve") == "naïve");
  // A handler's RequestError keeps its whole message (what() would stop at the NUL).
  const ctl::RequestError e(ctl::kErrorFailed, "before\0after"s);
  CHECK(e.message() == "before\0after"s);
  CHECK(std::string(e.what()) == "before");
}

TEST_CASE("the command list is the spec table's") {
  for (const auto& c : ctl::command_specs()) {
    CAPTURE(c.name);
    CHECK(ctl::is_known_command(c.name));
  }
  CHECK(ctl::known_commands().size() == ctl::command_specs().size());
  CHECK(ctl::find_command_spec("load")->args.size() == 6);
}
