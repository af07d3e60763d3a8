// Parameters of the sheet model: grid, topology, solver, plasticity, coupling.
// Internal units: positions mm, time s, mass kg; hence force mN and compliance mm/mN = m/N.
#pragma once

#include <string_view>

#include "vec3.h"

namespace crease::sheet {

// A rectangular sheet of nodes_u x nodes_v nodes over width_mm x height_mm.
struct GridParams {
  int nodes_u = 15;                      // W, along u (short edge for A4)
  int nodes_v = 21;                      // H, along v
  double width_mm = 210.0;               // extent along u
  double height_mm = 297.0;              // extent along v
  double areal_density_g_per_m2 = 80.0;  // paper grammage
  double thickness_mm = 1.0;             // collision thickness (layers keep this apart)
  // World position of sheet point (0,0) when flat; flat sheet: u -> +x, v -> -y (printed face up),
  // turned by turn_deg about z through that point (180: u -> -x, v -> +y).
  Vec3 origin_mm{0.0, 297.0, 0.5};
  double turn_deg = 0.0;
};

enum class Diagonals { none, alternating, both };

// Seed 000's construction by default: structural links with alternating diagonals plus
// bending links to every node in the (2r+1)^2 box whose city-block distance is in
// [bend_min_city, bend_max_city]. 15x21 -> 874 + 7848 = 8722 links.
struct TopologyParams {
  Diagonals diagonals = Diagonals::alternating;
  int bend_box_radius = 4;
  int bend_min_city = 3;
  int bend_max_city = 8;
};

// The observed key-points pull the model through
//   springs:   seed 001 Eq. 4, a zero-length spring per key-point (SheetModel::set_targets,
//              compliance target_compliance_m_per_n), solved with the links every substep;
//   keypoints: seed 000 Eqs. 1-4, a P-controller on the velocities of the nodes around each
//              key-point (SheetModel::set_keypoints, gain keypoint_gain_per_s), every substep.
enum class Coupling { springs, keypoints };

[[nodiscard]] constexpr std::string_view coupling_name(Coupling c) noexcept {
  return c == Coupling::keypoints ? "keypoints" : "springs";
}
// Parses "springs" or "keypoints"; false (out untouched) for anything else.
[[nodiscard]] constexpr bool parse_coupling(std::string_view s, Coupling& out) noexcept {
  if (s == "springs") out = Coupling::springs;
  else if (s == "keypoints") out = Coupling::keypoints;
  else return false;
  return true;
}

struct SolverParams {
  int substeps = 10;                          // N_s (seed 001 Eq. 1: dt_s = dt / N_s)
  Vec3 gravity_mm_per_s2{0.0, 0.0, -9810.0};
  double damping_per_s = 1.0;                 // velocity damping, v *= 1 - damping*dt_s
  double max_speed_mm_per_s = 1000.0;  // clamp on node speed (hands fold slower); also bounds
                                       // the jump when a hidden part is seen again
  double compliance_structural_m_per_n = 1e-7;  // alpha of a structural link at stiffness 1
  double compliance_bending_m_per_n = 0.05;     // alpha of a bending link at stiffness 1
  double stiffness = 0.9;          // seed 000 default link stiffness coefficient (0..1]
  double crease_stiffness = 0.001; // stiffness of links crossing a crease (seed 000 code)
  // Elasto-plastic links (seed 001 III.C); plasticity_rate 0 disables it. With crease_strain
  // below, how the tracking model holds a fold nobody announced (crease-bench sheet_hold:
  // plugins/sheet_model/README.md): a bending link yields beyond 5 % strain and keeps 95 % of
  // what it is strained past that.
  double yield_strain = 0.05;      // eps_Y
  double plasticity_rate = 0.95;   // a in [0, 1)
  bool plastic_bending_only = true;
  // A crease inferred from the strain (0: off): a bending link whose |strain| passes this takes
  // crease_stiffness, as if a crease crossed it, until reset_rt (SheetModel::infer_creases_rt,
  // once per frame).
  double crease_strain = 0.03;
  // SheetRunner lets the links learn (plastic update, inferred creases) only while the model
  // fits what it sees: the mean key-point distance at most learn_fit_mm for learn_after_s in a
  // row, or nothing seen. A model still catching up with its observations (a first sighting, a
  // jump) strains its links with the solver's lag, not the sheet's shape.
  double learn_fit_mm = 2.0;
  double learn_after_s = 0.2;
  // The plastic update runs after every this many substeps, counted across frames (1: after
  // every substep). The rule depends on elongations only, not on time: a world stepping 1 ms
  // frames of a few substeps can update every few ms and pay a fraction of the link pass.
  int plasticity_every = 1;
  // How SheetRunner couples the observed key-points to the model (the model applies whatever
  // inputs it is given): see Coupling.
  Coupling coupling = Coupling::springs;
  // Key-point velocity coupling (seed 000 Eqs. 1-4): gain lambda, 1/s.
  double keypoint_gain_per_s = 10.0;
  // Zero-length target springs (seed 001 Eq. 4): alpha_input, m/N.
  double target_compliance_m_per_n = 1e-6;
  // Depth targets (SheetModel::set_normal_targets): alpha of a target of weight 1, m/N (a
  // target of weight w has alpha / w); along_normal: the spring acts along the model's normal at
  // its sheet point only (point-to-plane), else in 3-D like a target point.
  double depth_compliance_m_per_n = 0.05;
  bool depth_along_normal = true;
  // With depth_along_normal: the share of the tangential error the spring corrects too (0: the
  // normal only; 1: a 3-D spring). Depth says little about where along the surface a point lies,
  // but not nothing (the sheet's edges): without any of it the sheet slides as the flap turns.
  double depth_tangential_weight = 0.3;
  // With depth_along_normal: a target that carries the observed surface's normal (NormalTarget::
  // surface_normal) pulls along the bisector of it and the model's normal. Along the model's
  // normal alone, a flap that turns ahead of the model is pushed out along its tangent each frame
  // (its hinge rises off the crease); along the bisector the pull follows the chord of the turn.
  bool depth_surface_normal = true;
  // While depth targets arrive: a node no depth target pulls, lying within this of the sheet's
  // lowest node (on the table) and under another part of the sheet (a flap laid over it), keeps
  // its place along the table (mm; 0: off). Hidden paper under a layer stays where it lay; the
  // targets' pull on the rest of the sheet does not slide it.
  double depth_hold_hidden_mm = 1.5;
  // Strain limiting (strain_limit.h): structural links longer than (1 + max_strain) x their rest
  // length are shortened to it after each substep's contacts, in strain_limit_sweeps sweeps.
  // 0: off (the tracking model follows what it sees); the simulated world's paper does not
  // stretch.
  double max_strain = 0.0;
  int strain_limit_sweeps = 4;
  // Contacts: Coulomb friction coefficient against rigid shapes.
  double friction = 0.5;
  // ... and between layers (paper on paper; position-based: a node's slip over the triangle
  // under it in a substep is cancelled up to this times the depth the layer contact corrected).
  // 0: frictionless layers (the tracking model's default; the world's sheet takes its drawn
  // paper-paper figure).
  double layer_friction = 0.0;
  bool self_collision = true;
  // Layer contacts are enforced every this many substeps and always on the last one (a node
  // keeps its side for the whole frame, so one skipped substep cannot lose it).
  int self_collision_every = 2;
};

// How SheetRunner predicts the observed key-points to each model step (keypoint_predictor.h).
struct PredictorParams {
  double max_gap_s = 0.25;         // two observations further apart give no velocity
  double max_extrapolate_s = 0.2;  // an unseen key-point is predicted this long, then dropped
  bool bound_by_sheet = true;      // unseen key-points within their sheet distance of the seen
  double slack_mm = 1.0;           // the bound's allowance for observation noise
  // Nodes no key-point pulls move no faster than the fastest key-point seen within this many
  // seconds (SheetModel::set_unseen_speed_limit); 0: no such limit (max_speed_mm_per_s only).
  double unseen_speed_memory_s = 3.0;
};

struct SheetParams {
  GridParams grid;
  TopologyParams topology;
  SolverParams solver;
  PredictorParams predictor;
};

}  // namespace crease::sheet
