// Sequence files: both shipped folds load; malformed files are refused naming file, line, key.
#include "plugins/fold_sequence/fold_spec.h"

#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "core/errors.h"
#include "plugins/fold_sequence/states.h"

using namespace crease::fold;

namespace {

std::string shipped(const char* name) { return std::string(CREASE_SOURCE_DIR) + "/config/folds/" + name; }

std::string read_all(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// half.yaml with `from` replaced by `to` (which must occur), written to a temporary file.
std::string variant(const std::string& from, const std::string& to) {
  std::string text = read_all(shipped("half.yaml"));
  const auto at = text.find(from);
  REQUIRE_MESSAGE(at != std::string::npos, from);
  text.replace(at, from.size(), to);
  const std::string path = (std::filesystem::temp_directory_path() / "crease_fold_spec_test.yaml").string();
  std::ofstream(path) << text;
  return path;
}

// The line of half.yaml where `needle` first occurs (1-based).
int line_of(const std::string& needle) {
  const std::string text = read_all(shipped("half.yaml"));
  const auto at = text.find(needle);
  REQUIRE(at != std::string::npos);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

std::string error_of(const std::string& path) {
  try {
    (void)load_fold_file(path);
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("the shipped folds load") {
  const FoldSpec h = load_fold_file(shipped("half.yaml"));
  CHECK(h.name == "half");
  CHECK(h.via_count == 8);
  CHECK(h.fold_line_mm[0][1] == 148.5);
  CHECK(h.via_mm[1][2] == -60.3);  // [u, v, h]: h above the sheet is the sheet frame's -z
  CHECK(h.shift.fingers == 0x03);
  CHECK(h.shift_role == 1);  // the pinching (rubber) hand shifts
  CHECK(h.shift.at_mm[0] == 105.0);
  CHECK(h.shift_lift_mm == 100.0);
  CHECK(h.fixate.at_mm[0] == 165.0);  // grasp.fixate: where the fixing hand comes down
  CHECK(h.fixate.fingers == 0x03);
  CHECK(h.fixate.approach_height_mm == 30.0);
  CHECK(h.lay_mm[1] == 14.5);
  CHECK(h.bend_yaw_limited);  // bend.yaw_range_deg: the pad's turn with the sheet's heading
  CHECK(h.bend_yaw_reference_deg == 180.0);
  CHECK(h.bend_yaw_range_deg[0] == -10.0);
  CHECK(h.bend_yaw_range_deg[1] == 20.0);
  CHECK(h.lay_mm[2] == -22.0);
  CHECK(h.refixate_out_mm[0] == 255.0);
  CHECK(h.refixate_out_force_n == 0.5);
  CHECK(h.swipe_withdraw_mm[1] == -25.0);
  CHECK(h.swipe_withdraw_mm[2] == -26.0);
  CHECK(h.pinch_fingers == 0x11);
  CHECK(h.pinching_side == 0);      // the right hand pinches
  CHECK(h.pinch_force_n == 0.2);
  CHECK(h.prepinch_rad[3] == doctest::Approx(1.428));
  CHECK(h.pinch_rad[15] == doctest::Approx(0.77));  // THJ5 closed
  CHECK(h.has_release_stiffness);
  CHECK(h.release_ramp_s == 1.5);
  CHECK(h.posture_ramp_s == 0.3);
  CHECK(h.pinch_lost_mm == 50.0);
  CHECK(h.pinch_lost_s == 0.3);
  CHECK(h.fold_lost_mm == 100.0);
  CHECK(h.flap_seen_points == 10);  // the laid layer's printed face in view: it lies open
  CHECK(h.flap_seen_s == 0.3);
  CHECK(h.release_stiffness[15] == doctest::Approx(0.5));  // the thumb soft while it opens
  CHECK(h.release_stiffness[3] == doctest::Approx(2.0));
  REQUIRE(h.grasp_above_via_count == 1);
  CHECK(h.grasp_above_via_world[0]);  // frame: world, its z up as given
  CHECK(h.grasp_above_via_mm[0][0] == 200.0);
  CHECK(h.grasp_above_via_mm[0][2] == 300.0);
  CHECK(h.grasp_above_via_orientation[0][1] == 0.50756);
  REQUIRE(h.grasp_path_count == 2);
  CHECK(h.grasp_path_mm[1][1] == 282.5);
  CHECK(h.grasp_path_mm[1][2] == 35.5);  // 35.5 mm under the sheet: +z
  CHECK(h.timeout_s[static_cast<std::size_t>(S::follow_via)] == 15.0);
  CHECK(h.timeout_s[static_cast<std::size_t>(S::shift_approach)] == 20.0);
  CHECK(h.timeout_s[static_cast<std::size_t>(S::shift)] == 120.0);
  CHECK(h.timeout_s[static_cast<std::size_t>(S::idle)] == 0.0);
  const FoldSpec d = load_fold_file(shipped("diagonal.yaml"));
  CHECK(d.name == "diagonal");
  CHECK(d.pinching_side == 1);  // absent: seed 000's left hand
  CHECK(d.grasp_path_count == 0);
  for (int j = 0; j < kHandJoints; ++j) CHECK(d.prepinch_rad[j] == d.open_rad[j]);  // absent: open
  CHECK_FALSE(d.has_release_stiffness);  // absent: the controller's stiffness kept
  CHECK(d.release_ramp_s == d.posture_ramp_s);  // absent: ramp_s
  CHECK(d.pinch_lost_mm == 0.0);         // absent: not checked
  CHECK(d.pinch_lost_s == 0.0);
  CHECK(d.fold_lost_mm == 0.0);
  CHECK(d.flap_seen_points == 0);  // not given: not checked
  CHECK(d.fold_line_mm[1][0] == 210.0);
  CHECK(d.via_count == 5);
  CHECK(d.shift_role == 0);  // absent: the fixing hand shifts and fixates where it pressed
  CHECK(d.fixate.at_mm[0] == d.shift.at_mm[0]);
}

TEST_CASE("malformed sequence files name the file, the line and the key") {
  const std::string tmp = (std::filesystem::temp_directory_path() / "crease_fold_spec_test.yaml").string();
  SUBCASE("a missing file") { CHECK(error_of("/nonexistent/fold.yaml").find("/nonexistent/fold.yaml") == 0); }
  SUBCASE("YAML that does not parse") {
    const std::string e = error_of(variant("  at_mm: [105, 88.5]", "  at_mm: [105, 88.5"));
    CHECK(e.find(tmp + ":") == 0);
    CHECK(e.find("fold") != std::string::npos);
  }
  SUBCASE("an unknown key, at its line") {
    const int line = line_of("  force_n: 1.5");
    const std::string e = error_of(variant("  force_n: 1.5", "  forse_n: 1.5"));
    CHECK(e.find(tmp + ":" + std::to_string(line) + ":") == 0);
    CHECK(e.find("fold.shift.forse_n: unknown key") != std::string::npos);
  }
  SUBCASE("a yaw range that does not hold the drawn heading, or one without its reference") {
    const int line = line_of("  yaw_range_deg: [-10, 20]");
    const std::string e =
        error_of(variant("  yaw_range_deg: [-10, 20]", "  yaw_range_deg: [5, 20]"));
    CHECK(e.find(tmp + ":" + std::to_string(line) + ":") == 0);
    CHECK(e.find("fold.bend.yaw_range_deg") != std::string::npos);
    const std::string r = error_of(variant("  yaw_reference_deg: 180\n", ""));
    CHECK(r.find("fold.bend.yaw_reference_deg") != std::string::npos);
  }
  SUBCASE("a missing required key") {
    const std::string e = error_of(variant("  corner_mm: [105, 297]", ""));
    CHECK(e.find("fold.shift.corner_mm: required") != std::string::npos);
  }
  SUBCASE("an unknown tool frame") {
    const std::string swipe =
        "  tool: ff_pad\n  fingers: [ff, mf]             # pitched";  // the swipe's
    const int line = line_of(swipe);
    const std::string e =
        error_of(variant(swipe, "  tool: ff_bak\n  fingers: [ff, mf]             # pitched"));
    CHECK(e.find(tmp + ":" + std::to_string(line) + ":") == 0);
    CHECK(e.find("fold.swipe.tool: unknown tool frame 'ff_bak'") != std::string::npos);
  }
  SUBCASE("a missing lay point, where the fixing hand slides out to") {
    CHECK(error_of(variant("  lay_mm: [105, 14.5, 22]\n", "  {}\n"))
              .find("fold.fixate_layer.lay_mm: required") != std::string::npos);
    CHECK(error_of(variant("  out_mm: [255, 88.5]", "  out_mm: [255]")).find("fold.refixate.out_mm: expected a list of 2") !=
          std::string::npos);
  }
  SUBCASE(
      "the shift's hand: fixing or pinching; a pinching one needs where the fixing hand fixates") {
    CHECK(error_of(variant("  hand: pinching", "  hand: thumbs"))
              .find("fold.shift.hand: must be fixing or pinching") != std::string::npos);
    const std::size_t a = read_all(shipped("half.yaml")).find("  fixate: {");
    const std::size_t b = read_all(shipped("half.yaml")).find("}\n", a);
    REQUIRE(a != std::string::npos);
    const std::string fixate = read_all(shipped("half.yaml")).substr(a, b + 2 - a);
    CHECK(error_of(variant(fixate, ""))
              .find("fold.grasp.fixate: required when shift.hand is pinching") !=
          std::string::npos);
  }
  SUBCASE("an unknown finger") {
    const std::string e = error_of(variant("pinch_fingers: [th, ff]", "pinch_fingers: [th, xx]"));
    CHECK(e.find("fold.grasp.pinch_fingers: unknown finger 'xx'") != std::string::npos);
  }
  SUBCASE("a via point that is not three numbers") {
    const int line = line_of("[105, 255.8, 60.3]");
    const std::string e = error_of(variant("[105, 255.8, 60.3]", "[105, 255.8]"));
    CHECK(e.find(tmp + ":" + std::to_string(line) + ":") == 0);
    CHECK(e.find("fold.bend.via[1].at_mm: expected a list of 3 numbers") != std::string::npos);
  }
  SUBCASE("a quaternion off unit length") {
    const std::string e = error_of(variant("[-0.64504, 0.75289, 0.11116, -0.06877]", "[-0.7, 0, 0, 0.9]"));
    CHECK(e.find("fold.bend.via[1].orientation: must be a unit quaternion") != std::string::npos);
  }
  SUBCASE("a timeout of a state that does not exist") {
    const std::string e = error_of(variant("fold/bend/follow_via: 15", "fold/bend/folow_via: 15"));
    CHECK(e.find("fold.timeouts_s.fold/bend/folow_via: not a state") != std::string::npos);
  }
  SUBCASE("a force out of range") {
    const std::string e = error_of(variant("  force_n: 1.5", "  force_n: -1"));
    CHECK(e.find("fold.shift.force_n: must be in [0, 10], got -1") != std::string::npos);
  }
  SUBCASE("a stop deceleration below the acceleration") {
    const std::string e =
        error_of(variant("approach: {speed_mm_s: 80, accel_mm_s2: 400", "approach: {speed_mm_s: 80, accel_mm_s2: 4000"));
    CHECK(e.find("fold.motion.approach.stop_accel_mm_s2: must be at least accel_mm_s2") != std::string::npos);
  }
  SUBCASE("a pinching hand that is no side") {
    const int line = line_of("  pinching: right");
    const std::string e = error_of(variant("  pinching: right", "  pinching: both"));
    CHECK(e.find(tmp + ":" + std::to_string(line) + ":") == 0);
    CHECK(e.find("fold.hands.pinching: must be left or right, not 'both'") != std::string::npos);
  }
  SUBCASE("a pinch force out of range") {
    const std::string e = error_of(variant("  pinch_force_n: 0.2", "  pinch_force_n: 0"));
    CHECK(e.find("fold.grasp.pinch_force_n: must be in [0.01, 10], got 0") != std::string::npos);
  }
  SUBCASE("a grasp path longer than one arm goal holds") {
    std::string path = "  path:\n";
    for (int i = 0; i < 8; ++i) path += "    - {at_mm: [105, 338.5, -35.5]}\n";
    const std::string e = error_of(variant("  path:\n    - {at_mm: [105, 338.5, -35.5]}\n", path));
    CHECK(e.find("fold.grasp.path: expected at most 7 points before at_mm") != std::string::npos);
  }
  SUBCASE("a grasp path point that is not three numbers") {
    const std::string e = error_of(variant("    - {at_mm: [105, 282.5, -35.5]}", "    - {at_mm: [105, 282.5]}"));
    CHECK(e.find("fold.grasp.path[1].at_mm: expected a list of 3 numbers") != std::string::npos);
  }
  SUBCASE("an above_via point without its orientation") {
    const std::string e =
        error_of(variant(", orientation: [0.05114, 0.50756, -0.08625, 0.85576]}", "}"));
    CHECK(e.find("fold.grasp.above_via[0].orientation: required") != std::string::npos);
  }
  SUBCASE("an above_via point in an unknown frame") {
    const std::string e =
        error_of(variant("{frame: world, at_mm: [200", "{frame: table, at_mm: [200"));
    CHECK(e.find("fold.grasp.above_via[0].frame: expected sheet or world, got 'table'") !=
          std::string::npos);
  }
  SUBCASE("a prepinch posture of the wrong length") {
    const std::string e = error_of(variant("  prepinch_rad: [0, 0,", "  prepinch_rad: [0,"));
    CHECK(e.find("fold.hands.prepinch_rad: expected a list of 20 numbers") != std::string::npos);
  }
  SUBCASE("a negative release stiffness") {
    const std::string e = error_of(variant("  release_stiffness: [30, 30,", "  release_stiffness: [-30, 30,"));
    CHECK(e.find("fold.hands.release_stiffness: element 0 must be within [0, 655.35] N m/rad") != std::string::npos);
  }
  SUBCASE("a degenerate fold line") {
    const std::string e = error_of(variant("[[0, 148.5], [210, 148.5]]", "[[0, 148.5], [0.5, 148.5]]"));
    CHECK(e.find("fold.fold_line_mm: its end points are less than 1 mm apart") != std::string::npos);
  }
  std::remove(tmp.c_str());
}

TEST_CASE("tool and finger names") {
  CHECK(tool_index("ff_pad") == 0);
  CHECK(tool_index("th_back") == 9);
  CHECK(tool_index("flange") == 11);
  CHECK(tool_index("palm") == -1);
  CHECK(finger_index("th") == 4);
  CHECK(finger_index("thumb") == -1);
}
