// Reading URDF files: the shipped one, and broken ones whose errors must name the file, the
// line and the element (a missing tag, a bad number, an unknown parent link, bad XML).
#include "plugins/robot_model/urdf_reader.h"

#include <doctest/doctest.h>

#include <string>

#include "core/errors.h"
#include "robot_files.h"

using namespace crease::robot;

namespace {

const std::string& shipped_urdf() {
  static const std::string text = robot_files::read(robot_files::shipped("crease_robot.urdf"));
  return text;
}

// The message read_urdf throws for TEXT written as NAME.
std::string error_of(const std::string& name, const std::string& text) {
  const std::string path = robot_files::write(name, text);
  try {
    (void)read_urdf(path);
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  FAIL("no ConfigError for " << name);
  return {};
}

std::string at(const std::string& name, int line) {
  return robot_files::tmp_dir() + "/" + name + ":" + std::to_string(line) + ": ";
}

}  // namespace

TEST_CASE("the shipped URDF reads, and every link and joint element is indexed with its line") {
  const UrdfDocument doc = read_urdf(robot_files::shipped("crease_robot.urdf"));
  REQUIRE(doc.model);
  CHECK(doc.model->getName() == "crease_robot");
  CHECK(doc.model->getRoot()->name == "world");
  CHECK(doc.source.elements().size() == doc.model->links_.size() + doc.model->joints_.size());
  const int line = robot_files::line_of(shipped_urdf(), "<joint name=\"r_S2\"");
  const auto* e = doc.source.find("joint", "r_S2");
  REQUIRE(e != nullptr);
  CHECK(e->line == line);
  CHECK(doc.source.where("joint", "r_S2") ==
        robot_files::shipped("crease_robot.urdf") + ":" + std::to_string(line) + ": joint 'r_S2'");
  CHECK(doc.source.find("link", "r_S2") == nullptr);
  CHECK(doc.source.where("link", "nowhere") ==
        robot_files::shipped("crease_robot.urdf") + ": link 'nowhere'");
}

TEST_CASE("a missing tag names the joint and its line") {
  const std::string& urdf = shipped_urdf();
  SUBCASE("a revolute joint without <limit>") {
    const std::string bad = robot_files::remove_line(urdf, "<limit ", "<joint name=\"r_S2\"");
    const int line = robot_files::line_of(bad, "<joint name=\"r_S2\"");
    const std::string msg = error_of("no_limit.urdf", bad);
    CHECK(msg.find(at("no_limit.urdf", line) + "joint 'r_S2': ") == 0);
    CHECK(msg.find("does not specify limits") != std::string::npos);
  }
  SUBCASE("a joint without <child>") {
    const std::string bad = robot_files::remove_line(urdf, "<child ", "<joint name=\"r_WRJ2\"");
    const int line = robot_files::line_of(bad, "<joint name=\"r_WRJ2\"");
    const std::string msg = error_of("no_child.urdf", bad);
    CHECK(msg.find(at("no_child.urdf", line) + "joint 'r_WRJ2': ") == 0);
    CHECK(msg.find("missing a parent and/or child link") != std::string::npos);
  }
}

TEST_CASE("a bad number names the element and the line of the child holding it") {
  const std::string& urdf = shipped_urdf();
  SUBCASE("in a joint's <origin>") {
    const std::string bad =
        robot_files::replace(urdf, "xyz=\"0 0 0.117\"", "xyz=\"0 0 0.1x7\"", "<joint name=\"r_S2\"");
    const int line = robot_files::line_of(bad, "0.1x7");
    const std::string msg = error_of("bad_origin.urdf", bad);
    CHECK(msg.find(at("bad_origin.urdf", line) + "joint 'r_S2' <origin>: ") == 0);
    CHECK(msg.find("0.1x7") != std::string::npos);
  }
  SUBCASE("in a joint's <limit>") {
    const std::string bad = robot_files::replace(urdf, "upper=\"0.34906585\"", "upper=\"0.35deg\"",
                                                 "<joint name=\"l_MFJ4\"");
    const int line = robot_files::line_of(bad, "0.35deg");
    const std::string msg = error_of("bad_limit.urdf", bad);
    CHECK(msg.find(at("bad_limit.urdf", line) + "joint 'l_MFJ4' <limit>: ") == 0);
  }
  SUBCASE("in a link's collision geometry") {
    const std::string bad = robot_files::replace(urdf, "<sphere radius=\"0.009\"/>", "<sphere radius=\"nine\"/>",
                                                 "<link name=\"r_mfknuckle\"");
    // urdfdom drops the broken <collision> and goes on; the reader refuses the file.
    const int line = robot_files::line_of(bad, "nine");
    const std::string msg = error_of("bad_radius.urdf", bad);
    CHECK(msg.find(at("bad_radius.urdf", line) + "link 'r_mfknuckle' <sphere>: ") == 0);
  }
}

TEST_CASE("an unknown parent link names the joint and the line of its <parent>") {
  const std::string bad = robot_files::replace(shipped_urdf(), "<parent link=\"l_link3\"/>",
                                               "<parent link=\"l_link33\"/>");
  const int line = robot_files::line_of(bad, "l_link33");
  const std::string msg = error_of("bad_parent.urdf", bad);
  CHECK(msg.find(at("bad_parent.urdf", line) + "joint 'l_E1' <parent>: ") == 0);
  CHECK(msg.find("l_link33") != std::string::npos);
}

TEST_CASE("bad XML names tinyxml2's line; a file that is not a robot or not there is refused") {
  const std::string bad = robot_files::replace(shipped_urdf(), "  </link>\n", "", "<link name=\"r_link3\"");
  const std::string msg = error_of("bad_xml.urdf", bad);
  CHECK(msg.find(robot_files::tmp_dir() + "/bad_xml.urdf:") == 0);
  CHECK(msg.find(": XML: ") != std::string::npos);
  CHECK(error_of("not_robot.urdf", "<?xml version=\"1.0\"?>\n<world name=\"x\"/>\n").find(
            at("not_robot.urdf", 2) + "the root element must be <robot>") == 0);
  CHECK_THROWS_WITH_AS((void)read_urdf(robot_files::tmp_dir() + "/missing.urdf"),
                       doctest::Contains("missing.urdf: cannot open"), crease::ConfigError);
}

TEST_CASE("after a refused file the next one reads (urdfdom's log handler is put back)") {
  (void)error_of("bad_again.urdf", "<robot name=\"r\"><joint name=\"j\" type=\"fixed\"/></robot>");
  const UrdfDocument doc = read_urdf_text("<robot name=\"r\"><link name=\"a\"/></robot>", "inline.urdf");
  CHECK(doc.model->getRoot()->name == "a");
}
