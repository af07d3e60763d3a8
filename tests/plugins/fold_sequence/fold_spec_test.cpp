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
  CHECK(h.via_count == 5);
  CHECK(h.fold_line_mm[0][1] == 148.5);
  CHECK(h.via_mm[1][2] == -153.5);  // [u, v, h]: h above the sheet is the sheet frame's -z
  CHECK(h.shift.fingers == 0x03);
  CHECK(h.fixate_layer.tool == 5);  // ff_back
  CHECK(h.pinch_fingers == 0x11);
  CHECK(h.timeout_s[static_cast<std::size_t>(S::follow_via)] == 15.0);
  CHECK(h.timeout_s[static_cast<std::size_t>(S::shift_approach)] == 20.0);
  CHECK(h.timeout_s[static_cast<std::size_t>(S::shift)] == 120.0);
  CHECK(h.timeout_s[static_cast<std::size_t>(S::idle)] == 0.0);
  const FoldSpec d = load_fold_file(shipped("diagonal.yaml"));
  CHECK(d.name == "diagonal");
  CHECK(d.fold_line_mm[1][0] == 210.0);
  CHECK(d.via_count == 5);
}

TEST_CASE("malformed sequence files name the file, the line and the key") {
  const std::string tmp = (std::filesystem::temp_directory_path() / "crease_fold_spec_test.yaml").string();
  SUBCASE("a missing file") { CHECK(error_of("/nonexistent/fold.yaml").find("/nonexistent/fold.yaml") == 0); }
  SUBCASE("YAML that does not parse") {
    const std::string e = error_of(variant("  at_mm: [150, 90]", "  at_mm: [150, 90"));
    CHECK(e.find(tmp + ":") == 0);
    CHECK(e.find("fold") != std::string::npos);
  }
  SUBCASE("an unknown key, at its line") {
    const int line = line_of("  force_n: 1.5");
    const std::string e = error_of(variant("  force_n: 1.5", "  forse_n: 1.5"));
    CHECK(e.find(tmp + ":" + std::to_string(line) + ":") == 0);
    CHECK(e.find("fold.shift.forse_n: unknown key") != std::string::npos);
  }
  SUBCASE("a missing required key") {
    const std::string e = error_of(variant("  corner_mm: [0, 297]", ""));
    CHECK(e.find("fold.shift.corner_mm: required") != std::string::npos);
  }
  SUBCASE("an unknown tool frame") {
    const int line = line_of("  tool: ff_back");
    const std::string e = error_of(variant("  tool: ff_back", "  tool: ff_bak"));
    CHECK(e.find(tmp + ":" + std::to_string(line) + ":") == 0);
    CHECK(e.find("fold.fixate_layer.tool: unknown tool frame 'ff_bak'") != std::string::npos);
  }
  SUBCASE("an unknown finger") {
    const std::string e = error_of(variant("pinch_fingers: [th, ff]", "pinch_fingers: [th, xx]"));
    CHECK(e.find("fold.grasp.pinch_fingers: unknown finger 'xx'") != std::string::npos);
  }
  SUBCASE("a via point that is not three numbers") {
    const int line = line_of("[-5, 148.5, 153.5]");
    const std::string e = error_of(variant("[-5, 148.5, 153.5]", "[-5, 148.5]"));
    CHECK(e.find(tmp + ":" + std::to_string(line) + ":") == 0);
    CHECK(e.find("fold.bend.via[1].at_mm: expected a list of 3 numbers") != std::string::npos);
  }
  SUBCASE("a quaternion off unit length") {
    const std::string e = error_of(variant("[-0.49265, -0.50725, 0.50725, 0.49265]", "[-0.7, 0, 0, 0.9]"));
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
