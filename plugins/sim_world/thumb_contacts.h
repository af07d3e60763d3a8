// The thumb against the other fingers of its hand, for the hands' balance (hand_compliance.h):
// two covers pressed together push each other apart, as paper between them does. Without it a
// thumb closed past touching (a pinch's squeeze: reference_poses.h's pinch at THJ5 0.77) sank
// 2 mm into the index wherever no paper was between them, neither finger felt it, and a node
// of the sheet that slipped into that overlap read the whole overlap as the covers' compression.
// With it the pads stop at each other and both fingertips read the squeeze (what a real hand's
// taxels read when its thumb presses its index, paper or not).
//
// Pairs: every compliant shape of the thumb with every compliant shape of another finger of the
// same hand (configure). Geometry: the two shapes' cores' nearest points (closest_cores,
// shape_geometry.h), the
// overlap of the cores grown by their radii; contacts up to kGapMm apart are listed, as the
// sheet's are, so that the balance sees one about to close. Stiffness: both covers in series
// over contact_area_mm2.
//
// Units: mm, N. RT after configure(): no allocation.
#pragma once

#include <span>
#include <vector>

#include "plugins/sim_world/hand_compliance.h"
#include "plugins/sim_world/robot_shapes.h"

namespace crease::world {

class ThumbContacts {
 public:
  static constexpr double kGapMm = 3.0;
  static constexpr int kThumb = 4;  // WorldShape::finger of the thumb

  // Non-RT. SHAPES: the robot's (not owned, fixed from now on).
  void configure(std::span<const WorldShape> shapes, double contact_area_mm2);
  [[nodiscard]] int pairs(int side) const noexcept { return static_cast<int>(pairs_[side].size()); }

  // The pairs of SIDE at POSES (one per shape) closer than kGapMm into OUT (and each one's two
  // shapes into SHAPE_A, SHAPE_B); returns how many (at most OUT's size). RT.
  int measure_rt(int side, std::span<const Pose> poses, std::span<HandCompliance::Contact> out,
                 std::span<int> shape_a, std::span<int> shape_b) const noexcept;

 private:
  struct Pair {
    int a = -1, b = -1;  // a: the thumb's
    double stiffness_n_per_mm = 0;
    // The two shapes' bounding radii: centres farther apart than this (and the gap) cannot touch.
    double reach_mm = 0;
  };
  const WorldShape* shapes_ = nullptr;
  std::vector<Pair> pairs_[2];
};

}  // namespace crease::world
