#include "core/params.h"

#include <doctest/doctest.h>

#include <string>

namespace {
crease::Params parse(const std::string& yaml) {
  return crease::Params(YAML::Load(yaml), "sim.yaml", "plugins[0].params");
}
std::string error_of(auto&& fn) {
  try {
    fn();
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST_CASE("typed access with defaults and ranges") {
  const auto p = parse("gain: 2.5\nname: left\ncount: 3\nflag: true\n");
  CHECK(p.get<double>("gain") == 2.5);
  CHECK(p.get<std::string>("name") == "left");
  CHECK(p.get<int>("count") == 3);
  CHECK(p.get<bool>("flag"));
  CHECK(p.get<double>("missing", 7.0) == 7.0);
  CHECK(p.get_in_range<int>("count", 0, 1, 5) == 3);
}

TEST_CASE("errors name the file, line, column and key") {
  const auto p = parse("gain: fast\ncount: 9\nnested:\n  k: [1, 2]\n");
  CHECK(error_of([&] { (void)p.get<double>("gain"); }) ==
        "sim.yaml:1:7: plugins[0].params.gain: expected a number, got 'fast'");
  CHECK(error_of([&] { (void)p.get<double>("absent"); }).find("plugins[0].params.absent: required parameter is missing") !=
        std::string::npos);
  CHECK(error_of([&] { (void)p.get_in_range<int>("count", 0, 1, 5); }) ==
        "sim.yaml:2:8: plugins[0].params.count: must be in [1, 5], got 9");
  CHECK(error_of([&] { (void)p.child("nested").get<int>("k"); }) ==
        "sim.yaml:4:6: plugins[0].params.nested.k: expected an integer, got a list");
}

TEST_CASE("keys never read are reported, including inside opened child maps") {
  const auto p = parse("gain: 1\ngian: 2\nsub:\n  a: 1\n  b: 2\n");
  (void)p.get<double>("gain");
  (void)p.child("sub").get<int>("a");
  const auto unused = p.unused_keys();
  REQUIRE(unused.size() == 2);
  CHECK(unused[0] == "sim.yaml:2:7: plugins[0].params.gian");
  CHECK(unused[1] == "sim.yaml:5:6: plugins[0].params.sub.b");
}

TEST_CASE("a list of maps: each element named by its index, its unread keys reported") {
  const auto p = parse("links:\n  - {port: a, topic: x}\n  - {port: b, tpoic: y}\nnot_list: 3\nbad: [1]\n");
  const auto links = p.list("links");
  REQUIRE(links.size() == 2);
  CHECK(links[0].get<std::string>("port") == "a");
  (void)links[0].get<std::string>("topic");
  CHECK(links[1].get<std::string>("port") == "b");
  CHECK(error_of([&] { (void)links[1].get<std::string>("topic"); }) ==
        "sim.yaml:3:5: plugins[0].params.links[1].topic: required parameter is missing");
  const auto unused = p.unused_keys();
  REQUIRE(unused.size() == 3);
  CHECK(unused[0] == "sim.yaml:3:22: plugins[0].params.links[1].tpoic");
  CHECK(p.list("absent").empty());
  CHECK(error_of([&] { (void)p.list("not_list"); }) ==
        "sim.yaml:4:11: plugins[0].params.not_list: expected a list of maps");
  CHECK(error_of([&] { (void)p.list("bad"); }) == "sim.yaml:5:7: plugins[0].params.bad[0]: expected a map");
}

TEST_CASE("a non-map is refused") {
  CHECK(error_of([] { parse("[1, 2]"); }).find("expected a map of parameters") != std::string::npos);
}

TEST_CASE("paths resolve against the folder of the file the parameters came from") {
  const crease::Params p(YAML::Load("layout: markers/layout.yaml\nrecord: /tmp/rec\n"), "/etc/crease/sim.yaml",
                         "plugins[0].params");
  CHECK(p.get_path("layout") == "/etc/crease/markers/layout.yaml");
  CHECK(p.get_path("record") == "/tmp/rec");
  CHECK(p.get_path("cameras", "cameras") == "/etc/crease/cameras");
  CHECK(p.resolve_path("cam0/%06d.png") == "/etc/crease/cam0/%06d.png");
  CHECK(p.unused_keys().empty());  // read as paths, they count as read
  CHECK(error_of([&] { (void)p.get_path("replay_dir"); }).find("params.replay_dir: required parameter is missing") !=
        std::string::npos);
  // A control request's parameters have no file: relative to the working directory.
  const crease::Params r(YAML::Load("dir: rec"), "request", "cameras.params");
  CHECK(r.get_path("dir") == "rec");
}
