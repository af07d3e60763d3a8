// Collision shapes from <collision> elements: kinds, sizes, poses, surfaces, and the refusals.
#include "plugins/robot_model/collision_shapes.h"

#include <doctest/doctest.h>

#include <string>

#include "core/errors.h"
#include "robot_files.h"

using namespace crease::robot;

namespace {

// A robot of one link holding BODY (its <collision> elements), read from memory.
UrdfDocument one_link(const std::string& body) {
  return read_urdf_text("<robot name=\"t\">\n  <link name=\"l_tip\">\n" + body + "  </link>\n</robot>\n",
                        "shapes.urdf");
}

std::vector<CollisionShape> shapes(const std::string& body) {
  const UrdfDocument doc = one_link(body);
  return collision_shapes_of(*doc.model->getLink("l_tip"), doc.source);
}

std::string error_of(const std::string& body) {
  try {
    (void)shapes(body);
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  FAIL("no ConfigError");
  return {};
}

}  // namespace

TEST_CASE("spheres, boxes, cylinders and capsules with their sizes, poses and surfaces") {
  const auto s = shapes(
      "    <collision name=\"shell\"><origin xyz=\"0.01 0 0\"/><geometry><sphere radius=\"0.02\"/>"
      "</geometry></collision>\n"
      "    <collision name=\"cover\"><origin xyz=\"0 0 -0.001\" rpy=\"0 0 1.5707963267948966\"/>"
      "<geometry><box size=\"0.018 0.014 0.002\"/></geometry></collision>\n"
      "    <collision name=\"shell\"><geometry><cylinder radius=\"0.03\" length=\"0.1\"/></geometry>"
      "</collision>\n"
      "    <collision name=\"cover_capsule\"><origin xyz=\"0 0 0.01\"/><geometry>"
      "<cylinder radius=\"0.0085\" length=\"0.012\"/></geometry></collision>\n");
  REQUIRE(s.size() == 4);
  CHECK(s[0].link == "l_tip");
  CHECK(s[0].kind == ShapeKind::sphere);
  CHECK(s[0].surface == Surface::shell);
  CHECK(s[0].radius_m == 0.02);
  CHECK(s[0].link_from_shape.p.x() == doctest::Approx(0.01));

  CHECK(s[1].kind == ShapeKind::box);
  CHECK(s[1].surface == Surface::cover);
  CHECK(s[1].half_extents_m[0] == doctest::Approx(0.009));
  CHECK(s[1].half_extents_m[1] == doctest::Approx(0.007));
  CHECK(s[1].half_extents_m[2] == doctest::Approx(0.001));
  CHECK(s[1].link_from_shape.p.z() == doctest::Approx(-0.001));
  CHECK(s[1].link_from_shape.M.UnitX().y() == doctest::Approx(1.0));  // yaw 90 deg

  CHECK(s[2].kind == ShapeKind::cylinder);
  CHECK(s[2].radius_m == 0.03);
  CHECK(s[2].length_m == 0.1);

  CHECK(s[3].kind == ShapeKind::capsule);
  CHECK(s[3].surface == Surface::cover);
  CHECK(s[3].radius_m == 0.0085);
  CHECK(s[3].length_m == 0.012);  // between the cap centres
}

TEST_CASE("a mesh, an unknown surface or a capsule that is not a cylinder is refused at its line") {
  const std::string mesh =
      "    <collision name=\"shell\"><geometry><sphere radius=\"0.01\"/></geometry></collision>\n"
      "    <collision name=\"shell\"><geometry><mesh filename=\"tip.stl\"/></geometry></collision>\n";
  CHECK(error_of(mesh).find("shapes.urdf:4: link 'l_tip' <collision>: a mesh collision") == 0);
  CHECK(error_of("    <collision name=\"skin\"><geometry><sphere radius=\"0.01\"/></geometry></collision>\n")
            .find("shapes.urdf:3: link 'l_tip' <collision>: collision name 'skin'") == 0);
  CHECK(error_of("    <collision name=\"cover_capsule\"><geometry><box size=\"1 1 1\"/></geometry>"
                 "</collision>\n")
            .find("only a <cylinder> can be a capsule") != std::string::npos);
  CHECK(error_of("    <collision name=\"cover\"><geometry><box size=\"0.01 0 0.01\"/></geometry>"
                 "</collision>\n")
            .find("a box's size must be > 0") != std::string::npos);
}
