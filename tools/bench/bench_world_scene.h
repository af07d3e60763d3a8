// crease-bench world: the scene both simulators run, recorded from ours and replayed by MuJoCo.
//
// The scenario (both hands in contact): the right index (rubber cover) and the left index
// (fabric cover), palms turned forward and 30 deg down, descend at 10 mm/s from 8 mm above the
// sheet to 6 mm below its top (pressing), hold; the right drags 40 mm towards -y at 20 mm/s
// while the left keeps pressing; both lift 20 mm and hold. The arms' angles for every step are
// solved before anything is timed (robot_model ArmIk), so the timed part is the world's step
// and its commands only. The hand shapes' poses of every step of our run are what MuJoCo's
// mocap bodies follow (the same capsules, boxes, spheres and cylinders on the same paths).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "plugins/sim_world/shape_geometry.h"

namespace crease::bench::world_scene {

// One hand shape as MuJoCo needs it: geometry in mm, friction against paper, and its pose at
// the end of every step of our run.
struct MirroredShape {
  world::Geom geom;
  double friction = 0;
  std::vector<world::Pose> poses;  // one per step
};

// What a run left: the sheet's nodes (mm), from the start and at the end.
struct SheetEnd {
  std::vector<sheet::Vec3> start, end;
  double lowest_z_mm = 0;      // the lowest node centre over the run's end (table top z = 0)
  double wall_s = 0;           // time spent stepping
  double simulated_s = 0;
  [[nodiscard]] double rtf() const { return wall_s > 0 ? simulated_s / wall_s : 0.0; }
};

// Where the two fingertips first pressed (mm, world), for the end-state figures.
struct ScenePoints {
  sheet::Vec3 right_press, left_press;
};

struct MujocoOptions {
  std::string solver = "CG";  // PGS, CG or Newton (MuJoCo's names)
  int iterations = 50;
  double tolerance = 1e-6;
  double particle_radius_mm = 1.0;
  double sheet_thickness_mm = 1.0;  // ours: the particles' centres half this over the table top
  std::uint64_t max_steps = 0;  // 0: all
};

// Runs the scene's recorded shape paths in MuJoCo 2.2.2 with the sheet as a composite grid.
// Returns false (and prints why) when MuJoCo refuses the model.
bool run_mujoco(const std::vector<MirroredShape>& shapes, double dt_s, int nodes_u, int nodes_v, double spacing_mm,
                double sheet_mass_kg, double table_friction, const MujocoOptions& o, SheetEnd& out);

}  // namespace crease::bench::world_scene
