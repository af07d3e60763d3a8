// The hand's compliant joints: each of the 20 a torsional spring of the commanded stiffness
// about its commanded target, saturating at the joint's effort (URDF), stopped by its limits.
// Quasi-static, once per world step: the deflection dq = q - q_target balances
//   k dq = J^T f_contacts + tau_external,
// where each contact c (finger_contacts.h residuals: the cover's compression d_c at the
// current deflection, stiffness k_c, normal n_c) pushes with
//   f_c = k_c max(0, d_c + g_c . (dq - dq_old)),   g_c = J_c^T n_c
// (the shape moving along n_c compresses the cover further) along -n_c, and tau_external is
// any other joint torque (held fixed). The linear system
//   (K + sum_c k_c g_c g_c^T) dq = -sum_c k_c (d_c - g_c . dq_old) g_c + tau_external
// is solved with an active set: contacts that would pull drop out, gaps that would close join
// (the caller lists contacts a little apart too, depth < 0), joints that would pass a limit
// stop at it (and leave it when they pull away); a spring whose torque would pass the effort
// takes its secant stiffness there, round after round (a softening spring converges so).
// The arm is position-controlled (kinematic): its joints never deflect.
//
// Units: N, mm, rad; stiffness N m/rad and effort N m as the URDF (converted inside). RT after
// configure(): no allocation.
#pragma once

#include <array>
#include <span>

#include "plugins/robot_model/robot_layout.h"
#include "plugins/sim_world/finger_contacts.h"
#include "plugins/sim_world/side_kinematics.h"

namespace crease::world {

class HandCompliance {
 public:
  static constexpr int kJoints = robot::kHandJoints;
  static constexpr int kMaxContacts = 1024;
  using Joints = std::array<double, kJoints>;

  struct Limits {
    Joints lower_rad{}, upper_rad{}, effort_nm{};
  };

  void configure(const Limits& limits) noexcept { limits_ = limits; }

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
  // joints are rigid (dq = 0; the covers alone give). RT.
  void solve_rt(const SideKinematics& kin, std::span<const Contact> contacts, const Joints& target,
                const Joints& stiffness_nm_per_rad, const Joints& tau_external_nmm, bool compliant, Joints& deflection,
                std::span<double> force_n) noexcept;

  // Joints that ended the last solve at their effort, or at a limit.
  [[nodiscard]] int saturated() const noexcept { return saturated_; }
  [[nodiscard]] int at_limit() const noexcept { return at_limit_; }
  // Rounds the last solve took (at most 100), and whether its factorisation failed.
  [[nodiscard]] int rounds() const noexcept { return rounds_; }
  [[nodiscard]] bool failed() const noexcept { return failed_; }

 private:
  Limits limits_;
  std::array<Joints, kMaxContacts> g_{};  // J^T n per contact, mm/rad
  int saturated_ = 0, at_limit_ = 0, rounds_ = 0;
  bool failed_ = false;
};

}  // namespace crease::world
