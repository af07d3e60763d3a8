// The hand's compliant joints: each of the 20 a torsional spring of the commanded stiffness
// about its commanded target, saturating at the joint's effort (URDF), stopped by its limits.
// Quasi-static, once per world step: the deflection dq = q - q_target balances
//   k dq = J^T f_contacts + tau_external,
// where each contact c (finger_contacts.h residuals: the cover's compression d_c at the
// current deflection, stiffness k_c, normal n_c) pushes with
//   f_c = k_c max(0, d_c + g_c . (dq - dq_old)),   g_c = J_c^T n_c
// (the shape moving along n_c compresses the cover further) along -n_c, and tau_external is
// any other joint torque (held fixed). dq minimises the convex potential
//   E(dq) = sum_j s_j(dq_j) + sum_c 1/2 k_c max(0, d_c + g_c . (dq - dq_old))^2 - tau_external . dq
// (s_j: the spring's energy, quadratic up to the effort, linear beyond) within the joints'
// limits, by projected Newton steps with backtracking: each round linearises at the current
// point (the contacts pressing there; a spring at its secant stiffness there; a joint held at a
// bound it pushes against), solves
//   (K + sum_c k_c g_c g_c^T) dq = -sum_c k_c (d_c - g_c . dq_old) g_c + tau_external,
// and halves the way there until E falls: the active sets cannot cycle, and the forces are
// those of the deflection returned (the caller lists contacts a little apart too, depth < 0).
// The arm is position-controlled (kinematic): its joints never deflect.
//
// Units: N, mm, rad; stiffness N m/rad and effort N m as the URDF (converted inside). RT after
// configure(): no allocation.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "plugins/robot_model/robot_layout.h"
#include "plugins/sim_world/finger_contacts.h"
#include "plugins/sim_world/side_kinematics.h"

namespace crease::world {

class HandCompliance {
 public:
  static constexpr int kJoints = robot::kHandJoints;
  using Joints = std::array<double, kJoints>;

  struct Limits {
    Joints lower_rad{}, upper_rad{}, effort_nm{};
  };

  // Non-RT: allocates room for MAX_CONTACTS contacts per solve (the caller's worst case: every
  // residual the sheet's nodes can give plus every shape on the table).
  void configure(const Limits& limits, int max_contacts = 64);
  // The most a joint's deflection may change in one solve (rad; default: no bound). The
  // contacts are linear about the step's pose: a bound keeps the solve where that holds.
  void set_max_step_rad(double rad) noexcept { max_step_rad_ = rad > 0 ? rad : 1e300; }

  // Contacts of this hand: residuals whose shape is compliant and on this side (the caller
  // filters), with their links. RT.
  // One shape against a node held fixed; or (link2 >= 0) two shapes of the hand pinching a
  // node between them: the same force on both, g = J1^T n1 + J2^T n2.
  struct Contact {
    int link = -1;
    Vec3 point, normal;
    double depth_mm = 0, stiffness_n_per_mm = 0;
    int link2 = -1;
    Vec3 point2, normal2;
  };

  // Solves for the new deflection. target, stiffness: the commanded ones (validated by the
  // caller). tau_external: N mm. deflection: in dq_old, out dq. force_n: per contact, its
  // normal force after the solve (N, >= 0; span of contacts.size()). compliant = false: the
  // joints are rigid (dq = 0; the covers alone give). More contacts than configured: the
  // first max_contacts are solved, the rest get no force, and truncated() counts the solve. RT.
  void solve_rt(const SideKinematics& kin, std::span<const Contact> contacts, const Joints& target,
                const Joints& stiffness_nm_per_rad, const Joints& tau_external_nmm, bool compliant, Joints& deflection,
                std::span<double> force_n) noexcept;

  // Joints that ended the last solve at their effort, or at a limit.
  [[nodiscard]] int saturated() const noexcept { return saturated_; }
  [[nodiscard]] int at_limit() const noexcept { return at_limit_; }
  // Rounds the last solve took (at most 100), and whether its factorisation failed.
  [[nodiscard]] int rounds() const noexcept { return rounds_; }
  [[nodiscard]] bool failed() const noexcept { return failed_; }
  // Solves that had more contacts than configured (since configure).
  [[nodiscard]] std::uint64_t truncated() const noexcept { return truncated_; }
  [[nodiscard]] int capacity() const noexcept { return static_cast<int>(g_.size()); }

 private:
  Limits limits_;
  std::vector<Joints> g_;          // J^T n per contact, mm/rad
  // Per contact: the joints its g_ row moves (a fingertip's chain, 4-5 of the 20), in order:
  // the sums over them are the full rows' sums, bit for bit (the rest add exact zeros).
  std::vector<std::array<std::uint8_t, kJoints>> nz_;
  std::vector<std::uint8_t> n_nz_;
  std::vector<std::uint8_t> on_;  // per contact: pushing in the current round
  std::vector<double> g_old_;     // per contact: g . dq_old (mm), fixed for a solve
  std::vector<double> depth_now_;  // per contact: its depth at the round's point (mm)
  std::uint64_t truncated_ = 0;
  double max_step_rad_ = 1e300;
  int saturated_ = 0, at_limit_ = 0, rounds_ = 0;
  bool failed_ = false;
};

}  // namespace crease::world
