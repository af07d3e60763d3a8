#include "tools/trials/trial_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "tools/trials/trial_json.h"

namespace crease::trials {
namespace {

std::string fmt(double v, const char* spec = "%.1f") {
  if (std::isnan(v)) return "-";
  if (std::isinf(v)) return "inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, spec, v);
  return buf;
}

}  // namespace

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  for (double& x : v)
    if (std::isnan(x)) x = std::numeric_limits<double>::infinity();
  std::sort(v.begin(), v.end());
  const auto n = static_cast<double>(v.size());
  const auto rank = static_cast<std::size_t>(std::max(1.0, std::ceil(p / 100.0 * n)));
  return v[std::min(rank, v.size()) - 1];
}

std::string row(const TrialResult& r) {
  const Score& s = r.score;
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "trial %d seed=%llu end=%s states=%d last=%s t=%.1fs fold_line_mm=%s angle_deg=%s corners_mm=%s "
                "retained_deg=%s stretch=%s slip_mm=%s hands_clear=%d success=%d",
                r.index, static_cast<unsigned long long>(r.seed), r.end.c_str(), r.fold_states,
                r.last_fold_state.empty() ? "-" : r.last_fold_state.c_str(), r.fold_time_s, fmt(s.fold_line_mm).c_str(),
                fmt(s.fold_angle_deg).c_str(), fmt(s.corners_mm).c_str(), fmt(s.retained_deg).c_str(),
                fmt(s.max_stretch, "%.3f").c_str(), fmt(s.slip_mm).c_str(), r.hands_clear ? 1 : 0, r.success ? 1 : 0);
  std::string out = buf;
  if (!r.success) out += " why=\"" + r.failure + "\"";
  return out;
}

std::string summary_line(const std::vector<TrialResult>& results, const std::string& fold, bool faults) {
  std::vector<double> line, angle, corners;
  double retained_min = std::numeric_limits<double>::quiet_NaN(), time = 0;
  int success = 0;
  for (const TrialResult& r : results) {
    success += r.success ? 1 : 0;
    line.push_back(r.score.fold_line_mm);
    angle.push_back(r.score.fold_angle_deg);
    corners.push_back(r.score.corners_mm);
    const double kept = std::isnan(r.score.retained_deg) ? 0.0 : r.score.retained_deg;
    retained_min = std::isnan(retained_min) ? kept : std::min(retained_min, kept);
    time += r.fold_time_s;
  }
  const double mean = results.empty() ? std::numeric_limits<double>::quiet_NaN() : time / double(results.size());
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "trials: fold=%s n=%zu success=%d faults=%d fold_line_mm_p95=%s angle_deg_p95=%s corners_mm_p95=%s "
                "retained_deg_min=%s mean_s=%s",
                fold.c_str(), results.size(), success, faults ? 1 : 0, fmt(percentile(line, 95)).c_str(),
                fmt(percentile(angle, 95)).c_str(), fmt(percentile(corners, 95)).c_str(), fmt(retained_min).c_str(),
                fmt(mean).c_str());
  return buf;
}

nlohmann::json summary_json(const std::vector<TrialResult>& results, const std::string& fold, std::uint64_t seed,
                            bool faults) {
  nlohmann::json trials = nlohmann::json::array();
  int success = 0;
  for (const TrialResult& r : results) {
    trials.push_back(to_json(r));
    success += r.success ? 1 : 0;
  }
  return {{"fold", fold},
          {"seed", seed},
          {"faults", faults},
          {"n", results.size()},
          {"success", success},
          {"summary", summary_line(results, fold, faults)},
          {"trials", trials}};
}

}  // namespace crease::trials
