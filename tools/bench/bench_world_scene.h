// crease-bench world: the scenes both simulators run, scripted for ours and replayed by MuJoCo.
//
// Three scenes, both hands in contact in each:
//  - press_drag: the right index (rubber cover) and the left index (fabric cover), palms turned
//    forward and 30 deg down, descend at 10 mm/s from 8 mm over the sheet to 6 mm below its top
//    (pressing); the right drags 40 mm towards -y at 20 mm/s while the left keeps pressing;
//    both lift 20 mm. Probes: the sheet under each fingertip.
//  - pinch: the sheet's corner over the table's near edge (the sim_world pinch test's pose)
//    pinched between the right thumb and index, lifted 50 mm at 5 mm/s, while the left index
//    presses the sheet's far half onto the table. Probe: the pinched point (rise, slip).
//  - fold: fold_script below. Probes: the pinched point's slip over the bend, the far edge's
//    distance from the near edge and the fold's angle at the end.
// Every step's arm and hand commands are computed before anything is timed (robot_model ArmIk),
// so the timed part is the world's step and its commands only. The hand shapes' poses of every
// step of our run are what MuJoCo's mocap bodies follow (the same geometry on the same paths).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "plugins/robot_model/robot_model.h"
#include "plugins/sim_world/sim_world.h"

namespace crease::bench::world_scene {

using ArmQ = world::World::ArmJoints;
using HandQ = world::World::HandJoints;

// One scene: the world's parameters and both sides' commands for every step.
struct Script {
  std::string name;
  world::WorldParams params;
  std::vector<std::array<ArmQ, 2>> arm;    // [step][side]
  std::vector<std::array<HandQ, 2>> hand;  // [step][side]
  std::array<HandQ, 2> stiffness{};        // N m/rad, held
  std::vector<sheet::Vec3> probes;         // sheet points (mm, flat sheet) whose motion is scored
  std::size_t mark_step = 0;               // a step whose state is kept (the pinch's lift start)
  std::size_t mark2_step = 0;              // another (the fold: the bend's end); 0: none
};

// False (printed why) when an arm cannot reach the scene's poses.
bool press_drag_script(const robot::RobotModel& model, bool quick, Script& out);
bool pinch_script(const robot::RobotModel& model, Script& out);
// The half fold of sim_world_fold (from beyond the far edge): the right pinches the far edge's
// middle, bends it over the crease on a half circle in 6 s while the left index presses the near
// half, the left slides out, the pinch opens and both hands leave; 3 s on, the end state.
bool fold_script(const robot::RobotModel& model, Script& out);

// One hand shape as MuJoCo needs it: geometry in mm, friction against paper, its pose at the end
// of every step of our run.
struct MirroredShape {
  world::Geom geom;
  double friction = 0;
  world::ShapeRole role = world::ShapeRole::finger;
  int side = 0, fingertip = -1;
  std::vector<world::Pose> poses;
};

// What a run left: the sheet's nodes (mm) at the start, at the mark step and at the end.
struct SheetRun {
  std::vector<sheet::Vec3> start, mark, mark2, end;
  double lowest_z_mm = 0;  // the lowest node centre at the end (table top z = 0)
  double wall_s = 0;       // time spent stepping
  double simulated_s = 0;
  [[nodiscard]] double rtf() const { return wall_s > 0 ? simulated_s / wall_s : 0.0; }
};

struct MujocoOptions {
  std::string solver = "CG";  // PGS, CG or Newton (MuJoCo's names)
  int iterations = 50;
  double tolerance = 1e-6;
  double particle_radius_mm = 1.0;
  double sheet_thickness_mm = 1.0;  // ours: the particles' centres half this over the table top
};

// Replays the recorded shape paths in MuJoCo 2.2.2 with the sheet as a composite grid of the
// scene's grid and mass, over a table of the scene's extent. False (printed why) when MuJoCo
// refuses the model.
bool run_mujoco(const Script& scene, const std::vector<MirroredShape>& shapes, double table_friction,
                const MujocoOptions& o, SheetRun& out);

}  // namespace crease::bench::world_scene
