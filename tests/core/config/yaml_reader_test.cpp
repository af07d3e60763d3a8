// did_you_mean: the closest candidate within edit distance 2 (case-insensitive), the first of
// equally close ones; its bounded distance (length gap and row minimum cut-offs) gives what
// the whole dynamic programme gives.
#include "core/config/yaml_reader.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cctype>
#include <random>
#include <string>
#include <vector>

namespace cfg = crease::config;

namespace {
// The whole table, no cut-off: the reference.
std::size_t full_distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) == std::tolower(static_cast<unsigned char>(b[j - 1]));
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (same ? 0 : 1)});
    }
  }
  return d[a.size()][b.size()];
}

std::string reference_guess(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_d = 3;
  for (const auto& c : candidates) {
    const std::size_t d = full_distance(word, c);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  return best;
}
}  // namespace

TEST_CASE("did_you_mean suggests within distance 2, case-insensitively, and nothing farther") {
  const std::vector<std::string> keys = {"plugin_dirs", "daemon", "loops", "plugins", "safety"};
  CHECK(cfg::did_you_mean("plugin", keys) == "plugins");
  CHECK(cfg::did_you_mean("LOOPS", keys) == "loops");
  CHECK(cfg::did_you_mean("lops", keys) == "loops");
  CHECK(cfg::did_you_mean("demon", keys) == "daemon");
  CHECK(cfg::did_you_mean("dmn", keys).empty());                     // distance 3
  CHECK(cfg::did_you_mean(std::string(5000, 'p'), keys).empty());    // lengths too far apart
  CHECK(cfg::did_you_mean("", {"ab", "abcd"}) == "ab");
  CHECK(cfg::did_you_mean("safety", keys) == "safety");
}

TEST_CASE("did_you_mean equals the whole dynamic programme on random words") {
  std::mt19937 rng(7);
  const std::string alphabet = "abAB_";
  const auto word = [&](std::size_t max_len) {
    std::string w(rng() % (max_len + 1), ' ');
    for (char& c : w) c = alphabet[rng() % alphabet.size()];
    return w;
  };
  for (int i = 0; i < 3000; ++i) {
    std::vector<std::string> candidates;
    for (int k = 0; k < 4; ++k) candidates.push_back(word(7));
    const std::string w = word(9);
    CAPTURE(w);
    CHECK(cfg::did_you_mean(w, candidates) == reference_guess(w, candidates));
  }
}
