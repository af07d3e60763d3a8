// Contact constraints of the sheet: nodes against rigid shapes (found by ODE's collision
// detection, enforced every substep with Coulomb friction) and nodes against triangles of
// other layers (each node keeps the side it started the frame on, at least `thickness`
// away, so layers never pass through each other). Candidates come from detect_rt (with a
// margin that may cover several frames of motion); select_rt keeps, once per frame, those
// that pass the per-frame tests; solve_rt enforces the kept ones. Nodes within kSelfSkipCells + 1 grid cells of a triangle's first corner are not
// tested against it: a sheet cannot fold onto itself that tightly at this resolution, and
// skipping them keeps curved (unfolded) regions free of spurious contacts.
// Detection, per grid cell (its two triangles share a box): blocks of 32 nodes whose box
// misses the cell's box grown by the reach are skipped, the rest are screened 8 at a time
// (AVX2 when the CPU has it) against that box and the sheet-neighbour rule, and the few
// survivors get the exact tests (plane distance, barycentric projection). The cost grows
// with cells x blocks: fine for the default 15 x 21 sheet and a few times larger.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "collision_world.h"
#include "layer_select.h"
#include "shape_contacts.h"
#include "sheet_params.h"
#include "topology.h"
#include "vec3.h"

namespace crease::sheet {

struct ContactStats {
  int shape_contacts = 0;     // node-shape candidates this frame
  int self_pairs = 0;         // node-triangle candidates this frame
  int self_candidates = 0;    // node-triangle candidates of the last detection
  std::uint64_t dropped = 0;  // candidates lost to full buffers, since start
};

class ContactSolver {
 public:
  // Allocates every buffer (configure time).
  void configure(const Topology& topo, const GridParams& grid, const SolverParams& solver);

  // Before the substeps. margin_mm: how far a node may move until the next detection.
  // The candidates found are also the active ones (what solve_rt enforces).
  // lateral_mm: layer contacts also when the node's projection lies up to this far outside
  // the triangle (beyond the usual tolerance), for candidates kept over several frames.
  void detect_rt(std::span<const Vec3> x, const CollisionWorld* world, double margin_mm,
                 double lateral_mm = 0.0) noexcept;
  // Once per frame between detections: the active candidates are those of the last
  // detection that pass detect_rt's tests with this frame's margin (shapes: within half the
  // thickness + margin of their surface; layers: plane distance < thickness + margin and the
  // projection inside the triangle), each layer contact taking the side the node is on now.
  void select_rt(std::span<const Vec3> x, double margin_mm) noexcept;
  // Every substep, after the links. w: inverse masses (0 = pinned). with_self: also the
  // layer contacts (else only the rigid shapes).
  void solve_rt(std::span<Vec3> x, std::span<const Vec3> prev, std::span<const double> w,
                bool with_self = true) noexcept;

  [[nodiscard]] const ContactStats& stats() const noexcept { return stats_; }
  // Screens nodes without AVX2 and selects without AVX-512 even when the CPU has them (tests
  // compare the two).
  void force_scalar(bool on) noexcept {
    use_simd_ = has_simd_ && !on;
    use_select_simd_ = has_select_simd_ && !on;
    shape_active_.force_scalar(on);
  }

 private:
  struct ShapePair {
    std::int32_t node;
    Vec3 normal;
    double offset;  // surface: dot(normal, y) = offset
  };
  using SelfPair = LayerPair;

  void detect_self_rt(std::span<const Vec3> x, double margin_mm, double lateral_mm) noexcept;

  const Topology* topo_ = nullptr;
  double half_thickness_ = 0.5, thickness_ = 1.0, friction_ = 0.5, layer_friction_ = 0.0;
  bool self_enabled_ = true;
  bool has_simd_ = false, use_simd_ = false;  // AVX2 node screening (runtime check)
  bool has_select_simd_ = false, use_select_simd_ = false;  // AVX-512 select (layer_select.h)
  std::vector<ShapePair> shape_pairs_;
  int n_shape_ = 0;
  std::vector<SelfPair> self_pairs_;
  int n_self_ = 0;
  ShapeContacts shape_active_;  // selected each frame from shape_pairs_ (self_active_: self_pairs_)
  std::vector<SelfPair> self_active_;
  int n_self_active_ = 0;
  std::vector<std::int32_t> cand_tris_;  // distinct triangles of self_pairs_
  int n_cand_tris_ = 0;
  std::vector<std::uint32_t> tri_stamp_;  // per triangle: detection stamp when in cand_tris_
  std::uint32_t stamp_ = 0;
  std::vector<Vec3> tri_n_;               // per candidate triangle, this frame: (b - a) x (c - a)
  double cell_mm_ = 20.0;  // a triangle whose box grown by the reach spans > 3 cells is torn
  std::vector<std::int32_t> node_gi_, node_gj_;  // grid column / row of each node
  std::vector<float> fx_, fy_, fz_;              // node positions for screening (padded)
  std::vector<std::int32_t> gi_, gj_;            // node_gi_ / node_gj_ padded
  std::vector<float> block_box_;                 // per block of screened nodes: min xyz, max xyz
  ContactStats stats_;
  static constexpr int kSelfSkipCells = 2;
};

}  // namespace crease::sheet
