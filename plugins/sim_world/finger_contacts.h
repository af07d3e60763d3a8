// Two-way contacts between the robot's shapes and the world's sheet, solved inside every
// substep of the sheet (sheet::SubstepContacts), with the table under each touched node.
//
// Geometry. A node stands for its cell of the sheet: the patch of its tangent plane spanning
// half the node spacing each way (clipped at the sheet's edges), so a fingertip cannot sink
// between nodes. For each node a shape may touch, the patch point deepest in the shape is found
// (the patch point below the shape's core, three projections), and the node is kept half the
// sheet's thickness outside the shape's surface there: pushed along the sheet's normal when the
// shape meets the patch face-on (within 60 deg; the distance scaled so that a tilted face
// clears), along the shape's normal when it meets it edge-on (a finger pushing the sheet's
// edge). A tilted fingertip therefore presses the sheet down, never squeezes it out sideways:
// sideways it acts through friction only.
//
// Normal. The contacts of one node (up to kMaxShapesPerNode shapes and the table) are solved
// together, exactly, as one small XPBD block: shape contacts are compliant (the cover's
// stiffness per mm^2 times the node's area), the table rigid. A node pressed between a finger
// and the table, or pinched between two fingers, thus carries the force the covers' compression
// says, whatever the node's mass (a Gauss-Seidel pass would give a node of a few mg almost
// none).
//
// Friction. Coulomb, per contact, with its own coefficient (the shape's material against
// paper; the table's): in the substep the node moves to the point minimising
//   1/2 |u - a|^2 + sum_k c_k |u - s_k|,    c_k = w mu_k lambda_k (mm),
// in the tangent plane: a the node's move after the normal solve, s_k the move of contact k's
// surface (the shape's material point, 0 for the table). One contact gives position-based
// friction (stick within c, else slide by c); several give the quasi-static answer a sheet
// pressed onto the table by a moving finger needs: it moves with the finger exactly when the
// finger's friction beats the table's.
//
// A layer under the node. A touched node lifted off the table that lies on a node of another
// layer resting on the table (the nearest under it within half a cell's diagonal, one to four
// thicknesses lower, at least 3 grid cells away on the sheet; found at the step's start) rests
// on that node instead of the table: a rigid contact one thickness over it, with paper-paper
// friction against its motion. What presses the node onto it then loads it too: the node under
// moves to the minimiser of the same problem between the table (still) and the layer above (as
// it just moved), each at the full press. So a finger's press holds a stack's layers to each
// other and to the table; the layers' own contacts (sheet::ContactSolver) bound their friction
// by the depth each pass corrects, a few mg's worth (a rubber finger slid over a folded sheet's
// top layer).
//
// Reaction. The force each node's contacts exert is the shape's reaction (opposite). The hands'
// quasi-static balance (hand_compliance.h) reads, before each step, the contacts the step's
// start leaves with the shapes where the new commands put them (measure_rt: their depth is the
// covers' compression: the nodes pressed onto the table hold still), and the friction each
// shape felt in the last step, averaged over its substeps, as a force and a moment about the
// world origin.
//
// Units: mm, kg, s inside (the sheet's); forces out in N, moments in N mm. RT after
// configure(): no allocation.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "plugins/sheet_model/sheet_model.h"
#include "plugins/sheet_model/substep_contacts.h"
#include "plugins/sim_world/robot_shapes.h"

namespace crease::world {

class FingerContacts final : public sheet::SubstepContacts {
 public:
  static constexpr int kMaxShapesPerNode = 4;
  static constexpr int kMaxNodeContacts = kMaxShapesPerNode + 1;  // + the table or the layer under

  struct Config {
    double table_height_mm = 0;
    double table_extent_mm[4] = {-1e9, 1e9, -1e9, 1e9};  // x_min, x_max, y_min, y_max
    double table_friction = 0.35;  // paper on the table
    double layer_friction = 0.4;   // paper on paper: a node pressed onto a layer lying on the table
    bool hand_contacts = true;     // false: no shape touches the sheet
    bool finger_friction = true;
    bool table_friction_on = true;
    double margin_mm = 2.0;        // candidates: nodes this close (plus the step's motion)
  };

  // A contact the hands' balance sees (measure_rt): a shape pressing a node that something
  // holds (the table, or a layer lying on it), the node taken as fixed; or two shapes of two fingers
  // (or a finger and the palm) pinching a node nothing else holds (shape2 >= 0), which then only passes the squeeze from one to
  // the other. Per shape: its surface point and the direction it pushes the node (away from
  // the shape). depth: the covers' compression (mm; a pinch: both together); negative: the gap,
  // listed up to 3 mm so that the balance sees a contact about to close. stiffness: of the
  // contact (N/mm; a pinch: both covers in series). A node nothing holds, touched by one shape,
  // gives nothing: the finger pushes it away (its force, a few mg's inertia and the sheet's
  // bending, is left to the substeps).
  struct Residual {
    int shape = -1;
    Vec3 point;
    Vec3 normal;
    int shape2 = -1;
    Vec3 point2, normal2;
    double depth_mm = 0;
    double stiffness_n_per_mm = 0;
  };

  // Per shape, from the substeps of the last step (averages, N and N mm about the world
  // origin): the friction on the shape, and the normal push the block solves gave (for the
  // figures; the hands' balance takes the normal force from the residual contacts instead).
  struct ShapeLoad {
    Vec3 friction_n, friction_moment_nmm;
    Vec3 normal_n;
    int nodes = 0;  // nodes in contact with it at the step's end
  };

  // Allocates (configure time). The sheet gives the grid, node areas and thickness; SHAPES
  // (not owned, fixed in size and place from now on) are the robot's.
  void configure(const sheet::SheetModel& sheet, std::span<const WorldShape> shapes, const Config& cfg);
  void set_table_friction(double mu) noexcept { cfg_.table_friction = mu; }
  // How far shape S may spring back towards its undeflected pose in the coming steps (mm):
  // nodes that far beyond its reach are candidates too, and listed as gaps (measure_rt). RT.
  void set_springback(int s, double mm) noexcept { springback_mm_[s] = std::max(0.0, mm); }

  // Before the sheet's step of dt_s: the nodes each shape may touch in it (the shapes' pose0 ->
  // pose1). x, v: the sheet's positions and velocities. RT.
  void begin_step_rt(std::span<const Vec3> x, std::span<const Vec3> v, double dt_s) noexcept;
  // sheet::SubstepContacts
  void solve_rt(std::span<Vec3> x, std::span<const Vec3> prev, std::span<const double> w, int substep, int substeps,
                double dt_s) noexcept override;
  [[nodiscard]] double max_push_mm(double dt_s) const noexcept override;
  // Per node, the friction its contacts (shapes and the table under it) can take in the last
  // substep, mu F summed, over 1 g: the sheet's strain limit moves firmly held nodes least.
  [[nodiscard]] std::span<const double> hold_mass_kg() const noexcept override { return hold_kg_; }
  static constexpr double kHoldAccelMmS2 = 9810.0;
  // The contacts between the nodes touched in the last step (at positions x) and the shapes at
  // POSES (one per shape): residuals(). RT.
  // GAPS false: the contacts of positive depth only (what a step's end reports), the same as
  // those among the full list.
  void measure_rt(std::span<const Pose> poses, std::span<const Vec3> x, bool gaps = true) noexcept;
  // After the step: measure_rt at the shapes' pose1 without gaps (residuals() then lists the
  // contacts of positive depth only), and each shape's count of nodes. RT.
  void end_step_rt(std::span<const Vec3> x) noexcept;

  [[nodiscard]] std::span<const Residual> residuals() const noexcept { return {residual_.data(), std::size_t(n_residual_)}; }
  [[nodiscard]] const ShapeLoad& load(int shape) const noexcept { return load_[shape]; }
  // Candidate pairs dropped (a node near more than kMaxShapesPerNode shapes, or full buffers).
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }
  [[nodiscard]] int touched_nodes() const noexcept { return n_touched_; }

 private:
  struct Touched {
    std::int32_t node = 0;
    int n_shapes = 0;
    std::int32_t shape[kMaxShapesPerNode] = {};
    Vec3 eu, ev, en;                  // the patch's axes (unit: two tangent to the sheet, its normal)
    double ulo = 0, uhi = 0, vlo = 0, vhi = 0;  // its extent along them, mm
    double area_mm2 = 0;
    std::int32_t support =
        -1;  // a node of another layer under this one, lying on the table (-1: none)
  };
  struct Contact {  // one of a node's contacts in a substep
    Vec3 n;
    double pen = 0, alpha = 0, mu = 0;  // penetration (mm), compliance / dt_s^2 (1/kg), friction
    Vec3 surface_move;                  // of the contact's surface over the substep
    Vec3 point;
    int shape = -1;  // kTable, kSupport (the layer under), else the robot's shape
    double lambda = 0;
  };

  static constexpr int kTable = -1, kSupport = -2;
  static constexpr double kInactiveReachMm =
      2.0;                               // contacts this far apart still enter a node's block
  static constexpr double kGapMm = 3.0;  // measure_rt: contacts this far apart still listed
  // Of two contacts of a node with one rigid body, is the one of penetration a the one to keep?
  // Both inside: the nearer exit; else the deeper (a penetrating one beats a gap).
  static bool better_exit(double a, double b) noexcept { return a > 0 && b > 0 ? a < b : a > b; }
  struct Geometry {  // a node's contact with a shape
    Vec3 n;           // the direction the node is pushed (unit)
    double pen = 0;   // how far along n until it clears the shape by half the thickness (mm)
    Vec3 point;       // the shape's surface point
  };
  // The node at x in a shape's frame (the queries below work there: one transform in, two out).
  struct Local {
    Vec3 x, eu, ev;  // the node, its patch's tangent axes
  };
  [[nodiscard]] static Local to_local(const Pose& pose, const Touched& t, Vec3 x_local) noexcept {
    return {x_local, pose.inverse_rotate(t.eu), pose.inverse_rotate(t.ev)};
  }
  // A lower bound on the distance of the node's patch from the shape (mm): the node's from the
  // core, less the shape's growth and the patch's reach.
  [[nodiscard]] double patch_distance_bound(int shape, Vec3 x_local) const noexcept;
  [[nodiscard]] static Vec3 deepest_patch_point(const WorldShape& s, const Touched& t,
                                                const Local& l) noexcept;
  [[nodiscard]] Geometry geometry(const WorldShape& s, const Pose& pose, const Touched& t,
                                  const Local& l) const noexcept;
  // Two shapes that can pinch a node: two fingers of one hand, or a finger and the palm (a node
  // in the crook of one finger is left to the substeps: its joints do not feel it).
  [[nodiscard]] static bool pinch_pair(const WorldShape& a, const WorldShape& b) noexcept {
    return a.side == b.side && (a.finger != b.finger || a.finger < 0);
  }
  [[nodiscard]] bool may_pinch(const Touched& t) const noexcept;
  int gather_rt(const Touched& t, Vec3 p, double dt_s, Contact* c, bool& any,
                std::span<const Vec3> x, std::span<const Vec3> prev) const noexcept;
  [[nodiscard]] bool on_table(Vec3 p) const noexcept;
  [[nodiscard]] double table_mu() const noexcept {
    return cfg_.table_friction_on ? cfg_.table_friction : 0.0;
  }
  void find_supports_rt(std::span<const Vec3> x, int nx, int ny) noexcept;
  void carry_support_rt(const Touched& t, const Contact& support, std::span<Vec3> x,
                        std::span<const Vec3> prev, double w_support, double dt_s) noexcept;
  static Vec3 normal_rt(Contact* c, int m, double w) noexcept;
  static Vec3 friction_rt(const Contact* c, int m, double w, double dt_s, Vec3 u0, Vec3* fric_on_node) noexcept;
  void solve_node_rt(const Touched& t, std::span<Vec3> x, std::span<const Vec3> prev,
                     std::span<const double> w, double dt_s, double weight) noexcept;

  Config cfg_;
  const sheet::SheetModel* sheet_ = nullptr;
  const WorldShape* shapes_ = nullptr;
  int n_shapes_ = 0;
  int grid_w_ = 0, grid_h_ = 0;
  double du_ = 0, dv_ = 0, half_thickness_ = 0.5;
  double patch_reach_ = 0;  // mm: a patch's farthest point from its node (half its cell's diagonal)
  std::vector<double> node_area_mm2_;
  std::vector<double> hold_kg_;             // per node: hold_mass_kg (0: not touched)
  std::vector<std::int32_t> slot_of_node_;  // -1: not touched this step
  std::vector<Touched> touched_;
  int n_touched_ = 0;
  std::vector<std::uint8_t> shape_near_;    // this step: may touch the sheet
  std::vector<double> springback_mm_;       // per shape: set_springback
  std::vector<double> bound_reach_mm_;      // per shape: its core's growth plus patch_reach_
  std::vector<Pose> pose_now_, pose_before_;  // per shape, at the current substep's end and start
  std::vector<ShapeLoad> load_;
  std::vector<Residual> residual_;
  int n_residual_ = 0;
  double max_push_mm_ = 0;
  std::uint64_t dropped_ = 0;
  // Node buckets over the sheet's box in x, y (counting sort, rebuilt every step).
  static constexpr int kMaxCells = 64;
  std::vector<std::int32_t> cell_start_, cell_nodes_;
  std::vector<std::int32_t> cell_of_;  // per node: its bucket this step
  std::vector<Vec3> cell_points_;      // the nodes' positions in bucket order (as cell_nodes_)
};

}  // namespace crease::world
