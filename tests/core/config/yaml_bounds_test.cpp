// Tests for core/config/yaml_bounds.h: the size limit points at the first byte past it, the
// node count expands aliases (an alias bomb of 10^10 leaves is refused at the alias where the
// count passes the limit, from one linear pass), and an alias cycle is refused.
#include "core/config/yaml_bounds.h"

#include <doctest/doctest.h>

#include <random>
#include <string>

#include "core/errors.h"

namespace cfg = crease::config;

namespace {

std::string error_of(const std::string& text, const cfg::YamlBounds& bounds) {
  try {
    (void)cfg::load_bounded_yaml(text, "bomb.yaml", bounds);
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

// LEVELS lines; line k+1 is "aK: &aK [*aJ, ... ten times]", line 1 ten scalars: the last
// anchor stands for 10^LEVELS leaves.
std::string alias_bomb(int levels) {
  std::string t = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int k = 1; k < levels; ++k) {
    const std::string prev = "*a" + std::to_string(k - 1);
    t += "a" + std::to_string(k) + ": &a" + std::to_string(k) + " [" + prev;
    for (int i = 1; i < 10; ++i) t += ", " + prev;
    t += "]\n";
  }
  return t;
}

}  // namespace

TEST_CASE("a text up to max_bytes loads; one byte more names the line and column of that byte") {
  const std::string text = "a: 1\nbb: [2, 3]\n";  // 16 bytes
  cfg::YamlBounds b;
  b.max_bytes = text.size();
  CHECK(cfg::load_bounded_yaml(text, "f.yaml", b)["bb"][1].as<int>() == 3);
  b.max_bytes = 7;  // the 8th byte, 'b' at line 2, column 3, is one too many
  CHECK(error_of(text, b) == "bomb.yaml:2:3: (file): larger than 7 bytes (the limit of a configuration file)");
  // The default: 1 MiB.
  CHECK(cfg::YamlBounds{}.max_bytes == 1048576);
  const std::string big = "# " + std::string(std::size_t{1} << 20, 'x') + "\n";
  CHECK(error_of(big, {}).find("bomb.yaml:1:1048577: (file): larger than 1048576 bytes") == 0);
}

TEST_CASE("nodes are counted with aliases expanded: an alias bomb fails at the alias past the limit") {
  // 10^3 leaves from 3 lines: loads under the default limit, not under a limit of 1000.
  CHECK(cfg::load_bounded_yaml(alias_bomb(3), "f.yaml", {})["a2"][9][9][9].as<std::string>() == "x");
  cfg::YamlBounds small;
  small.max_nodes = 1000;
  // Nodes: the map 1, then per level its key and its list: a0 1+11, a1 1+111, a2 1+1111.
  // At a2, 125 nodes are counted; each alias adds 111: the 8th (index 7) passes 1000.
  CHECK(error_of(alias_bomb(3), small) ==
        "bomb.yaml:3:45: a2[7]: more than 1000 nodes with aliases expanded (the limit of a configuration file)");
  // 10^10 leaves (the walk of any tree of them would take hours): refused from one pass of
  // ten lines, at the fifth level, where the count first passes 100,000.
  const std::string e = error_of(alias_bomb(10), {});
  CHECK(e.find("bomb.yaml:5:") == 0);
  CHECK(e.find(": a4[") != std::string::npos);
  CHECK(e.find("more than 100000 nodes with aliases expanded") != std::string::npos);
  // Without aliases the count is the plain node count: 1 map + 2 keys + 2 lists + 5 items = 10.
  small.max_nodes = 10;
  CHECK_NOTHROW((void)cfg::load_bounded_yaml("a: [1, 2]\nb: [3, 4, 5]\n", "f.yaml", small));
  small.max_nodes = 9;
  CHECK(error_of("a: [1, 2]\nb: [3, 4, 5]\n", small).find("bomb.yaml:2:11: b[2]: more than 9 nodes") == 0);
}

TEST_CASE("an alias inside the node it names is a cycle; YAML errors keep their place") {
  CHECK(error_of("a: &x [1, *x]\n", {}) == "bomb.yaml:1:11: a[1]: an alias inside the node it names (a cycle)");
  CHECK(error_of("a: &x {k: *x}\n", {}).find("a.k: an alias inside the node it names") != std::string::npos);
  CHECK(error_of("a: *nothing\n", {}).find("bomb.yaml:1:4: (syntax):") == 0);
  CHECK(error_of("a: [1, 2\n", {}).find("(syntax)") != std::string::npos);
  // The path names keys and indices down to the node: the 7th node is q's first item.
  cfg::YamlBounds b;
  b.max_nodes = 6;
  CHECK(error_of("p:\n  - {q: [1, 2]}\n", b).find("bomb.yaml:2:10: p[0].q[0]: more than 6 nodes") == 0);
}

// load_bounded_yaml skips its counting pass for a text without aliases too short to hold more
// than max_nodes nodes at 3 per byte plus one (node_count_cannot_pass, with one per byte to
// spare). The claim itself, on random texts of YAML's punctuation: counted with max_nodes at
// 3 (bytes + 1), none passes it, also before a syntax error ends the count.
TEST_CASE("a text without aliases has at most 3 nodes per byte plus one; shorter texts skip the count") {
  std::mt19937 rng(11);
  const std::string alphabet = "?:-[]{},\n a!&#|>'\"";
  int counted = 0;
  for (int i = 0; i < 20000; ++i) {
    std::string t(1 + rng() % 16, ' ');
    for (char& c : t) c = alphabet[rng() % alphabet.size()];
    cfg::YamlBounds b;
    b.max_nodes = 3 * (t.size() + 1);
    CAPTURE(t);
    try {
      (void)cfg::count_yaml_nodes(t, "r.yaml", b);
      ++counted;
    } catch (const crease::ConfigError& e) {
      CHECK(std::string(e.what()).find("(syntax)") != std::string::npos);  // never "more than"
    }
  }
  CHECK(counted > 1000);
  cfg::YamlBounds b;
  b.max_nodes = 100;
  CHECK(cfg::node_count_cannot_pass(std::string(24, 'x'), b));
  CHECK_FALSE(cfg::node_count_cannot_pass(std::string(25, 'x'), b));
  CHECK_FALSE(cfg::node_count_cannot_pass("a: *x", b));  // an alias: counted whatever the size
  // Below the bound the verdicts are the counting pass's: a syntax error keeps its place.
  CHECK(error_of("a: [1, 2\n", {}) == error_of("a: [1, 2\n" + std::string(30000, '#'), {}));
}
