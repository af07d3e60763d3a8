// crease-trials' HTML page from trials built by hand: a plot for a trial with samples ("no
// samples" for one without), every state path and failure text escaped, no NaN written into
// the SVG, and a force spike among 5000 samples kept by the plot's decimation (each window's
// largest value).
#include "tools/trials/trial_report.h"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

using namespace crease::trials;

namespace {

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + what.size())) ++n;
  return n;
}

// A trial with 3 states, a right-hand force spike of SPIKE_N at sample SPIKE_AT among N samples
// (20 ms apart, about 1 N otherwise), the left hand's force missing (NaN) at one sample, the
// stretch NaN for the first 10 samples (no stretch measured yet).
TrialResult sampled_trial(int n, int spike_at, double spike_n) {
  TrialResult r;
  r.index = 0;
  r.seed = 7;
  r.fold = "half";
  r.end = "done";
  r.last_fold_state = "fold/shift&<pinch>";
  r.fold_states = 3;
  r.fold_time_s = n * kSeriesS;
  r.success = true;
  r.timeline = {{0.0, "reach", "start"},
                {0.4 * r.fold_time_s, "fold/shift/approach", "reached \"the corner\""},
                {0.7 * r.fold_time_s, "fold/shift&<pinch>", "contact"}};
  for (int k = 0; k < n; ++k) {
    SeriesSample x;
    x.t_s = k * kSeriesS;
    x.force_n[0] = k == spike_at ? spike_n : 1.0 + 0.2 * std::sin(k * 0.1);
    x.force_n[1] = k == n / 2 ? std::nan("") : 0.5;
    x.stretch = k < 10 ? std::nan("") : 0.002 + 0.00001 * k;
    r.series.push_back(x);
  }
  return r;
}

TrialResult unsampled_trial() {
  TrialResult r;
  r.index = 1;
  r.seed = 8;
  r.fold = "half";
  r.end = "aborted";
  r.last_fold_state = "reach";
  r.failure = "aborted in reach: <b>&\"bold\"</b>";
  r.score.fold_line_mm = std::nan("");
  r.timeline = {{0.0, "reach", ""}};
  return r;
}

// Every polyline of class CLS: its points (x, y) in SVG px. Found with find, not std::regex:
// libstdc++'s regex matches `[^"]*` one recursion per character, and a plot's 2000 points
// (~30 kB) overflow the stack under ASan at -O1.
std::vector<std::pair<double, double>> points_of(const std::string& html, const std::string& cls, int* lines) {
  const std::string open = "<polyline class=\"" + cls + "\" points=\"";
  std::vector<std::pair<double, double>> out;
  *lines = 0;
  for (std::size_t at = html.find(open); at != std::string::npos; at = html.find(open, at)) {
    ++*lines;
    at += open.size();
    const std::size_t close = html.find('"', at);
    REQUIRE(close != std::string::npos);
    std::istringstream points(html.substr(at, close - at));
    double x = 0, y = 0;
    char comma = 0;
    while (points >> x >> comma >> y) {
      REQUIRE(comma == ',');
      out.emplace_back(x, y);
    }
    at = close;
  }
  return out;
}

// The force axis' labels: (y px, value N) of each tick, bottom first.
std::vector<std::pair<double, double>> force_ticks(const std::string& html) {
  const std::regex label("<text class=\"fl\" x=\"[^\"]*\" y=\"([^\"]*)\"[^>]*>([^<]*)</text>");
  std::vector<std::pair<double, double>> out;
  for (std::sregex_iterator it(html.begin(), html.end(), label), end; it != end; ++it)
    out.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
  return out;
}

}  // namespace

TEST_CASE("the page: a plot per trial with samples, every text escaped, no NaN in the SVG") {
  const std::vector<TrialResult> results = {sampled_trial(200, 50, 12.0), unsampled_trial()};
  const std::string html = trials_html(results, "half", false);

  CHECK(html.rfind("<!DOCTYPE html>", 0) == 0);
  CHECK(html.find("</html>") != std::string::npos);
  CHECK(html.find("<script") == std::string::npos);
  CHECK(html.find("href=\"http") == std::string::npos);
  CHECK(html.find("src=") == std::string::npos);
  CHECK(count(html, "<svg") == 1);  // the trial with samples only
  CHECK(count(html, "no samples") == 1);
  CHECK(html.find("trials: fold=half n=2 success=1 faults=0") != std::string::npos);  // the summary line

  // The states: each path (escaped) in its band's tooltip, never raw.
  CHECK(html.find("<title>reach from 0.00 s: start</title>") != std::string::npos);
  CHECK(html.find("fold/shift/approach from 1.60 s: reached &quot;the corner&quot;") != std::string::npos);
  CHECK(html.find("fold/shift&amp;&lt;pinch&gt; from 2.80 s") != std::string::npos);
  CHECK(html.find("shift&<pinch>") == std::string::npos);
  CHECK(count(html, "class=\"state\"") == 3);  // the unsampled trial's state: no plot

  // The failure text escaped, never raw.
  CHECK(html.find("aborted in reach: &lt;b&gt;&amp;&quot;bold&quot;&lt;/b&gt;") != std::string::npos);
  CHECK(html.find("<b>") == std::string::npos);

  // No coordinate is "nan" or "inf"; the NaN samples are gaps.
  const std::regex coordinate(R"(\s(points|x|y|x1|y1|x2|y2|width|height)="([^"]*)\")");
  int coordinates = 0;
  for (std::sregex_iterator it(html.begin(), html.end(), coordinate), end; it != end; ++it, ++coordinates) {
    const std::string v = (*it)[2];
    CHECK_MESSAGE(v.find("nan") == std::string::npos, (*it)[0].str());
    CHECK_MESSAGE(v.find("inf") == std::string::npos, (*it)[0].str());
  }
  CHECK(coordinates > 50);
  int lines = 0;
  CHECK(points_of(html, "force-r", &lines).size() == 200);
  CHECK(lines == 1);
  CHECK(points_of(html, "force-l", &lines).size() == 199);
  CHECK(lines == 2);  // broken at the missing sample
  CHECK(points_of(html, "stretch", &lines).size() == 190);
  CHECK(lines == 1);  // starts after the first 10 samples
}

TEST_CASE("a 40 N spike among 5000 samples survives the decimation to at most 2000 points") {
  const std::vector<TrialResult> results = {sampled_trial(5000, 2717, 40.0)};
  const std::string html = trials_html(results, "half", false);
  int lines = 0;
  const auto right = points_of(html, "force-r", &lines);
  REQUIRE(!right.empty());
  CHECK(right.size() <= kPlotMaxPoints);
  CHECK(right.size() > kPlotMaxPoints / 2);
  CHECK(points_of(html, "stretch", &lines).size() <= kPlotMaxPoints);

  const auto ticks = force_ticks(html);
  REQUIRE(ticks.size() >= 2);
  CHECK(ticks.front().second == 0.0);
  const double y0 = ticks.front().first, v0 = ticks.front().second;
  const double y1 = ticks.back().first, v1 = ticks.back().second;
  const auto newtons = [&](double y) { return v0 + (y - y0) * (v1 - v0) / (y1 - y0); };
  double top_y = 1e9, spike_x = 0;
  for (const auto& [x, y] : right)
    if (y < top_y) {
      top_y = y;
      spike_x = x;
    }
  CHECK(newtons(top_y) == doctest::Approx(40.0).epsilon(0.005));
  // Drawn at its own time: sample 2717 of 0..4999 along the line (the ends within a window of theirs).
  const double along = (spike_x - right.front().first) / (right.back().first - right.front().first);
  CHECK(along == doctest::Approx(2717.0 / 4999).epsilon(0.003));
  // Everywhere else about 1 N (1 +- 0.2 N).
  int high = 0;
  for (const auto& [x, y] : right) high += newtons(y) > 1.3 ? 1 : 0;
  CHECK(high == 1);
}
