#include "plugins/sim_world/hand_compliance.h"

#include <algorithm>
#include <cmath>

namespace crease::world {
namespace {

constexpr int kN = HandCompliance::kJoints;
constexpr int kMaxRounds = 100;
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

void HandCompliance::solve_rt(const SideKinematics& kin, std::span<const Contact> contacts, const Joints& target,
                              const Joints& stiffness, const Joints& tau_external, bool compliant, Joints& dq,
                              std::span<double> force_n) noexcept {
  const int nc = std::min<int>(static_cast<int>(contacts.size()), kMaxContacts);
  for (int c = 0; c < nc; ++c) {
    g_[c].fill(0.0);
    kin.add_hand_jacobian_transpose(contacts[c].link, contacts[c].point, contacts[c].normal, g_[c]);
    if (contacts[c].link2 >= 0)
      kin.add_hand_jacobian_transpose(contacts[c].link2, contacts[c].point2, contacts[c].normal2, g_[c]);
  }
  saturated_ = 0;
  at_limit_ = 0;
  if (!compliant) {
    dq.fill(0.0);
    for (int c = 0; c < nc; ++c) force_n[c] = contacts[c].stiffness_n_per_mm * std::max(0.0, contacts[c].depth_mm);
    return;
  }
  const Joints old = dq;
  enum State : unsigned char { free_joint, locked };
  State st[kN];
  double lock_at[kN], k_eff[kN], k_full[kN], tmax[kN];
  for (int j = 0; j < kN; ++j) {
    st[j] = free_joint;
    lock_at[j] = 0;
    k_full[j] = k_eff[j] = 1000.0 * std::max(0.0, stiffness[j]);
    tmax[j] = 1000.0 * limits_.effort_nm[j];
  }
  bool on[kMaxContacts];
  for (int c = 0; c < nc; ++c) on[c] = contacts[c].depth_mm > 0;
  // Depth of contact c at deflection dq, linearised about the step's.
  auto depth = [&](int c, const Joints& d) {
    double s = contacts[c].depth_mm;
    for (int j = 0; j < kN; ++j) s += g_[c][j] * (d[j] - old[j]);
    return s;
  };

  Joints sol = old;
  rounds_ = 0;
  failed_ = false;
  for (int round = 0; round < kMaxRounds; ++round) {
    ++rounds_;
    double a[kN][kN] = {};
    double r[kN];
    for (int j = 0; j < kN; ++j) {
      r[j] = tau_external[j];
      a[j][j] = kEpsNmmPerRad + k_eff[j];
    }
    for (int c = 0; c < nc; ++c) {
      if (!on[c]) continue;
      const double kc = contacts[c].stiffness_n_per_mm;
      double gd = 0;
      for (int j = 0; j < kN; ++j) gd += g_[c][j] * old[j];
      const double rc = -kc * (contacts[c].depth_mm - gd);
      for (int i = 0; i < kN; ++i) {
        const double gi = g_[c][i];
        if (gi == 0.0) continue;
        r[i] += rc * gi;
        for (int j = 0; j < kN; ++j) a[i][j] += kc * gi * g_[c][j];
      }
    }
    for (int j = 0; j < kN; ++j) {
      if (st[j] != locked) continue;
      for (int i = 0; i < kN; ++i) {
        if (i == j) continue;
        r[i] -= a[i][j] * lock_at[j];
        a[i][j] = a[j][i] = 0.0;
      }
      a[j][j] = 1.0;
      r[j] = lock_at[j];
    }
    if (!cholesky_solve(a, r)) {  // lost to rounding (A is SPD by construction): the last iterate
      failed_ = true;
      break;
    }
    for (int j = 0; j < kN; ++j) sol[j] = r[j];

    bool changed = false;
    for (int c = 0; c < nc; ++c) {
      const double d = depth(c, sol);
      if (on[c] != (d > 0)) {
        on[c] = d > 0;
        changed = true;
      }
    }
    // The torque the contacts, the external load and the spring leave on each joint at the
    // solution: a joint at a limit stays there while it pushes into it.
    double net[kN];
    for (int j = 0; j < kN; ++j) net[j] = tau_external[j] - k_eff[j] * sol[j];
    for (int c = 0; c < nc; ++c) {
      if (!on[c]) continue;
      const double f = contacts[c].stiffness_n_per_mm * depth(c, sol);
      for (int j = 0; j < kN; ++j) net[j] -= f * g_[c][j];
    }
    for (int j = 0; j < kN; ++j) {
      if (st[j] == locked) {
        const bool at_upper = target[j] + lock_at[j] >= limits_.upper_rad[j];
        if (at_upper ? net[j] < 0 : net[j] > 0) {
          st[j] = free_joint;
          changed = true;
        }
        continue;
      }
      const double q = target[j] + sol[j];
      if (q < limits_.lower_rad[j] || q > limits_.upper_rad[j]) {
        st[j] = locked;
        lock_at[j] = std::clamp(q, limits_.lower_rad[j], limits_.upper_rad[j]) - target[j];
        changed = true;
        continue;
      }
      // The spring saturates at the effort: its secant stiffness there, converging from above
      // (a softening spring: each round's deflection is at most the next one's).
      const double k = std::fabs(k_full[j] * sol[j]) <= tmax[j] ? k_full[j] : tmax[j] / std::fabs(sol[j]);
      if (std::fabs(k - k_eff[j]) > 1e-9 * (k_full[j] + 1.0)) {
        k_eff[j] = k;
        changed = true;
      }
    }
    if (!changed) break;
  }
  dq = sol;
  for (int j = 0; j < kN; ++j) {
    saturated_ += st[j] != locked && k_eff[j] < k_full[j];
    at_limit_ += st[j] == locked;
  }
  for (int c = 0; c < nc; ++c) force_n[c] = on[c] ? contacts[c].stiffness_n_per_mm * std::max(0.0, depth(c, sol)) : 0.0;
}

}  // namespace crease::world
