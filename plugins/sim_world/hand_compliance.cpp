#include "plugins/sim_world/hand_compliance.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace crease::world {
namespace {

constexpr int kN = HandCompliance::kJoints;
constexpr int kMaxRounds = 100;
constexpr double kAtBoundRad = 1e-9;   // a joint this near a bound is at it (the last step's rounding)
constexpr double kEpsNmmPerRad = 1e-2;  // keeps a joint nothing holds solvable (0.01 N mm per rad: nothing)
// In-place Cholesky solve of the SPD system A x = b (A overwritten). False if not SPD.
bool cholesky_solve(double a[kN][kN], double b[kN]) noexcept {
  for (int j = 0; j < kN; ++j) {
    double d = a[j][j];
    for (int k = 0; k < j; ++k) d -= a[j][k] * a[j][k];
    if (!(d > 0)) return false;
    a[j][j] = std::sqrt(d);
    for (int i = j + 1; i < kN; ++i) {
      double s = a[i][j];
      for (int k = 0; k < j; ++k) s -= a[i][k] * a[j][k];
      a[i][j] = s / a[j][j];
    }
  }
  for (int i = 0; i < kN; ++i) {
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= a[i][k] * b[k];
    b[i] = s / a[i][i];
  }
  for (int i = kN - 1; i >= 0; --i) {
    double s = b[i];
    for (int k = i + 1; k < kN; ++k) s -= a[k][i] * b[k];
    b[i] = s / a[i][i];
  }
  return true;
}

}  // namespace

void HandCompliance::configure(const Limits& limits, int max_contacts) {
  limits_ = limits;
  g_.assign(static_cast<std::size_t>(std::max(0, max_contacts)), Joints{});
  nz_.assign(g_.size(), {});
  n_nz_.assign(g_.size(), 0);
  on_.assign(g_.size(), 0);
  g_old_.assign(g_.size(), 0.0);
  depth_now_.assign(g_.size(), 0.0);
  truncated_ = 0;
}

void HandCompliance::solve_rt(const SideKinematics& kin, std::span<const Contact> contacts, const Joints& target,
                              const Joints& stiffness, const Joints& tau_external, bool compliant, Joints& dq,
                              std::span<double> force_n) noexcept {
  const int given = static_cast<int>(contacts.size());
  const int nc = std::min(given, capacity());
  if (given > nc) {
    ++truncated_;
    for (int c = nc; c < given; ++c) force_n[c] = 0.0;
  }
  for (int c = 0; c < nc; ++c) {
    g_[c].fill(0.0);
    kin.add_hand_jacobian_transpose(contacts[c].link, contacts[c].point, contacts[c].normal, g_[c]);
    if (contacts[c].link2 >= 0)
      kin.add_hand_jacobian_transpose(contacts[c].link2, contacts[c].point2, contacts[c].normal2, g_[c]);
    int n = 0;
    for (int j = 0; j < kN; ++j)
      if (g_[c][j] != 0.0) nz_[c][n++] = static_cast<std::uint8_t>(j);
    n_nz_[c] = static_cast<std::uint8_t>(n);
  }
  saturated_ = 0;
  at_limit_ = 0;
  if (!compliant) {
    dq.fill(0.0);
    for (int c = 0; c < nc; ++c) force_n[c] = contacts[c].stiffness_n_per_mm * std::max(0.0, contacts[c].depth_mm);
    return;
  }
  const Joints old = dq;
  double* g_old = g_old_.data();  // g_c . dq_old per contact: fixed for the solve
  for (int c = 0; c < nc; ++c) {
    g_old[c] = 0;
    for (int k = 0; k < n_nz_[c]; ++k) g_old[c] += g_[c][nz_[c][k]] * old[nz_[c][k]];
  }
  // The box each joint's deflection stays in: its limits, and within max_step_rad of the last.
  double lo[kN], hi[kN], k_full[kN], tmax[kN], k_eff[kN];
  for (int j = 0; j < kN; ++j) {
    lo[j] = std::max(limits_.lower_rad[j] - target[j], old[j] - max_step_rad_);
    hi[j] = std::min(limits_.upper_rad[j] - target[j], old[j] + max_step_rad_);
    if (lo[j] > hi[j]) lo[j] = hi[j] = std::clamp(old[j], limits_.lower_rad[j] - target[j], limits_.upper_rad[j] - target[j]);
    k_full[j] = 1000.0 * std::max(0.0, stiffness[j]);
    tmax[j] = 1000.0 * limits_.effort_nm[j];
  }
  // Depth of contact c at deflection d, linearised about the step's.
  auto depth = [&](int c, const double* d) {
    double v = contacts[c].depth_mm;
    for (int k = 0; k < n_nz_[c]; ++k) {
      const int j = nz_[c][k];
      v += g_[c][j] * (d[j] - old[j]);
    }
    return v;
  };
  // The potential the balance minimises (N mm): the springs (quadratic up to the effort, linear
  // beyond: convex), the covers' compression 1/2 k d^2, less the external torques' work.
  auto energy = [&](const double* d) {
    double e = 0;
    for (int j = 0; j < kN; ++j) {
      const double x = std::fabs(d[j]), xs = k_full[j] > 0 ? tmax[j] / k_full[j] : 0.0;
      e += 0.5 * kEpsNmmPerRad * x * x - tau_external[j] * d[j];
      if (k_full[j] > 0) e += x <= xs ? 0.5 * k_full[j] * x * x : tmax[j] * (x - 0.5 * xs);
    }
    for (int c = 0; c < nc; ++c) {
      const double v = depth(c, d);
      if (v > 0) e += 0.5 * contacts[c].stiffness_n_per_mm * v * v;
    }
    return e;
  };

  double cur[kN];
  for (int j = 0; j < kN; ++j) cur[j] = std::clamp(old[j], lo[j], hi[j]);
  double e_cur = energy(cur);
  std::uint8_t* on = on_.data();
  double* depth_now = depth_now_.data();  // per contact: its depth at cur, this round
  bool locked[kN] = {};
  rounds_ = 0;
  failed_ = false;
  // Projected Newton on the convex potential: each round linearises at the current point (the
  // contacts pressing there, each spring at its secant stiffness there, joints held at a bound
  // they push against), solves, and backtracks along the way to the solution until the
  // potential falls, so the active sets cannot cycle.
  for (int round = 0; round < kMaxRounds; ++round) {
    ++rounds_;
    for (int c = 0; c < nc; ++c) {
      depth_now[c] = depth(c, cur);
      on[c] = depth_now[c] > 0;
    }
    double grad[kN];
    for (int j = 0; j < kN; ++j) {
      k_eff[j] = std::fabs(k_full[j] * cur[j]) <= tmax[j] ? k_full[j] : tmax[j] / std::fabs(cur[j]);
      grad[j] = (kEpsNmmPerRad + k_eff[j]) * cur[j] - tau_external[j];
    }
    for (int c = 0; c < nc; ++c) {
      if (!on[c]) continue;
      const double f = contacts[c].stiffness_n_per_mm * depth_now[c];
      for (int k = 0; k < n_nz_[c]; ++k) grad[nz_[c][k]] += f * g_[c][nz_[c][k]];
    }
    // A joint at a bound stays there while the potential falls beyond it.
    for (int j = 0; j < kN; ++j) locked[j] = (cur[j] <= lo[j] + kAtBoundRad && grad[j] > 0) || (cur[j] >= hi[j] - kAtBoundRad && grad[j] < 0);

    // The Newton system at this point, before any joint is held: the springs' secant stiffness
    // and the pressing contacts.
    double a0[kN][kN] = {}, r0[kN];
    for (int j = 0; j < kN; ++j) {
      r0[j] = tau_external[j];
      a0[j][j] = kEpsNmmPerRad + k_eff[j];
    }
    for (int c = 0; c < nc; ++c) {
      if (!on[c]) continue;
      const double kc = contacts[c].stiffness_n_per_mm;
      const double rc = -kc * (contacts[c].depth_mm - g_old[c]);
      for (int a = 0; a < n_nz_[c]; ++a) {
        const int i = nz_[c][a];
        const double gi = g_[c][i];
        r0[i] += rc * gi;
        for (int b = 0; b < n_nz_[c]; ++b) a0[i][nz_[c][b]] += kc * gi * g_[c][nz_[c][b]];
      }
    }
    // The Newton step over the free joints. A free joint at a bound that the step would take
    // past it is held there too, and the step solved again: what is left descends.
    double r[kN];
    bool solved = false;
    for (int again = 0; again <= kN; ++again) {
      double a[kN][kN];
      std::memcpy(a, a0, sizeof a);
      std::memcpy(r, r0, sizeof r);
      for (int j = 0; j < kN; ++j) {
        if (!locked[j]) continue;
        for (int i = 0; i < kN; ++i) {
          if (i == j) continue;
          r[i] -= a[i][j] * cur[j];
          a[i][j] = a[j][i] = 0.0;
        }
        a[j][j] = 1.0;
        r[j] = cur[j];
      }
      if (!cholesky_solve(a, r)) break;  // lost to rounding (A is SPD by construction)
      solved = true;
      bool more = false;
      for (int j = 0; j < kN; ++j) {
        if (locked[j]) continue;
        if ((cur[j] <= lo[j] + kAtBoundRad && r[j] < cur[j]) || (cur[j] >= hi[j] - kAtBoundRad && r[j] > cur[j])) {
          locked[j] = true;
          more = true;
        }
      }
      if (!more) break;
      solved = false;
    }
    if (!solved) {  // keep the iterate
      failed_ = true;
      break;
    }
    double next[kN], step = 0;
    for (double t = 1.0; t > 1e-6; t *= 0.5) {
      for (int j = 0; j < kN; ++j) next[j] = std::clamp(cur[j] + t * (r[j] - cur[j]), lo[j], hi[j]);
      const double e = energy(next);
      if (e <= e_cur) {
        step = 0;
        for (int j = 0; j < kN; ++j) step = std::max(step, std::fabs(next[j] - cur[j]));
        for (int j = 0; j < kN; ++j) cur[j] = next[j];
        e_cur = e;
        break;
      }
    }
    if (step <= 1e-12) {
      // No descent. A free joint that the step takes out through a bound it is all but at
      // (closer than the smallest trial step moves it) bends the projected way uphill: put it
      // on that bound, where the next round holds it, and go on; else this is the minimum.
      bool snapped = false;
      for (int j = 0; j < kN; ++j) {
        if (locked[j]) continue;
        const double d = r[j] - cur[j];
        if (d < 0 && cur[j] - lo[j] < 1e-3 * -d) {
          cur[j] = lo[j];
          snapped = true;
        } else if (d > 0 && hi[j] - cur[j] < 1e-3 * d) {
          cur[j] = hi[j];
          snapped = true;
        }
      }
      if (!snapped) break;
      e_cur = energy(cur);
    }
  }
  for (int j = 0; j < kN; ++j) dq[j] = cur[j];
  for (int j = 0; j < kN; ++j) {
    const double q = target[j] + cur[j];
    // At a limit and pushing into it (as the last round found it).
    const bool at = locked[j] && (q <= limits_.lower_rad[j] + 1e-12 || q >= limits_.upper_rad[j] - 1e-12);
    at_limit_ += at;
    saturated_ += !at && std::fabs(k_full[j] * cur[j]) > tmax[j];
  }
  for (int c = 0; c < nc; ++c) force_n[c] = contacts[c].stiffness_n_per_mm * std::max(0.0, depth(c, cur));
}

}  // namespace crease::world
