// Hand postures and palm orientations the world's scenes share (its tests, crease-bench world):
// joint angles in rad, drivers/README.md §3 order; rotations in the world frame. Found on this
// robot's URDF, not calibrated on the real hands. Non-RT (scene set-up).
#pragma once

#include <kdl/frames.hpp>

#include <array>
#include <cmath>
#include <numbers>

#include "plugins/robot_model/robot_layout.h"
#include "plugins/robot_model/robot_model.h"
#include "plugins/sim_world/side_kinematics.h"

namespace crease::world::poses {

using HandQ = std::array<double, robot::kHandJoints>;

// Hand joint indices (drivers/README.md §3); `using namespace poses::joints` for the names alone.
inline namespace joints {
enum HandJoint { WRJ2, WRJ1, FFJ4, FFJ3, FFJ2, MFJ4, MFJ3, MFJ2, RFJ4, RFJ3, RFJ2, LFJ5, LFJ4, LFJ3, LFJ2,
                 THJ5, THJ4, THJ3, THJ2, THJ1 };
}  // namespace joints

// Only the index finger out: the others bent back to their J3 limit (-15 deg).
inline HandQ index_out() {
  HandQ h{};
  h[MFJ3] = h[RFJ3] = h[LFJ3] = -15.0 * std::numbers::pi / 180.0;
  return h;
}

// The thumb-index pinch found by a search over the index's and thumb's joints: the index curled
// pad up, the pads facing 4 mm apart at THJ5 0.696; THJ5 opens (0.3) and closes it (0.77 squeezes).
inline HandQ pinch_hand(double thj5) {
  HandQ h = index_out();
  h[FFJ4] = 0.201;
  h[FFJ3] = 1.428;
  h[FFJ2] = 0.321;
  h[THJ5] = thj5;
  h[THJ4] = 1.072;
  h[THJ3] = 0.027;
  h[THJ2] = -0.549;
  h[THJ1] = -0.117;
  return h;
}

// A world pose of SideKinematics (mm) as a KDL frame (m).
inline KDL::Frame to_kdl_frame(const Pose& p) {
  return KDL::Frame(KDL::Rotation(p.r[0], p.r[1], p.r[2], p.r[3], p.r[4], p.r[5], p.r[6], p.r[7], p.r[8]),
                    KDL::Vector(p.t.x, p.t.y, p.t.z) / 1000.0);
}

// A rotation from its z axis and a vector near its x axis (neither need be unit).
inline KDL::Rotation frame_from_z_x(KDL::Vector z, KDL::Vector x_hint) {
  z.Normalize();
  x_hint = x_hint - KDL::dot(x_hint, z) * z;
  x_hint.Normalize();
  return KDL::Rotation(x_hint, z * x_hint, z);
}

// The palm turned forward (+y) and down by BETA (rad), its palmar face down and forward (either
// hand: the left mirrors the right in its palm's x, so its thumb comes out on the other side).
inline KDL::Rotation palm_forward_down(double beta) {
  return frame_from_z_x({0, std::cos(beta), -std::sin(beta)}, {-1, 0, 0});
}

// The right palm hanging down, turned so that with the hand at HAND (a pinch_hand) the thumb pad
// faces straight down onto the index pad.
inline KDL::Rotation pinch_palm(const robot::RobotModel& model, const HandQ& hand) {
  const KDL::Rotation r0 = frame_from_z_x({0, 0, -1}, {1, 0, 0});
  SideKinematics k(model, robot::Side::right);
  k.update_rt(std::array<double, robot::kArmJoints>{}, hand);
  const KDL::Frame palm = to_kdl_frame(k.link_pose(k.link_index("r_palm")));
  const KDL::Frame th = to_kdl_frame(k.link_pose(k.link_index("r_thpad")));
  const KDL::Vector n = r0 * (palm.M.Inverse() * th.M.UnitZ()), down(0, 0, -1);
  const KDL::Vector axis = n * down;
  return KDL::Rotation::Rot2(axis / axis.Norm(), std::atan2(axis.Norm(), KDL::dot(n, down))) * r0;
}

}  // namespace crease::world::poses
