// Contact constraints of the sheet: nodes against rigid shapes (found by ODE's collision
// detection once per frame, enforced every substep with Coulomb friction) and nodes
// against triangles of other layers (a spatial hash once per frame; each node keeps the
// side it started the frame on, at least `thickness` away, so layers never pass through
// each other). Nodes within kSelfSkipCells grid cells of a triangle are not tested against
// it: a sheet cannot fold onto itself that tightly at this resolution, and skipping them
// keeps curved (unfolded) regions free of spurious contacts.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "collision_world.h"
#include "sheet_params.h"
#include "topology.h"
#include "vec3.h"

namespace crease::sheet {

struct ContactStats {
  int shape_contacts = 0;     // node-shape candidates this frame
  int self_pairs = 0;         // node-triangle candidates this frame
  std::uint64_t dropped = 0;  // candidates lost to full buffers, since start
};

class ContactSolver {
 public:
  // Allocates every buffer (configure time).
  void configure(const Topology& topo, const GridParams& grid, const SolverParams& solver);

  // Once per frame, before the substeps. margin_mm: how far a node may move in the frame.
  void detect_rt(std::span<const Vec3> x, const CollisionWorld* world, double margin_mm) noexcept;
  // Every substep, after the links. w: inverse masses (0 = pinned).
  void solve_rt(std::span<Vec3> x, std::span<const Vec3> prev, std::span<const double> w) noexcept;

  [[nodiscard]] const ContactStats& stats() const noexcept { return stats_; }

 private:
  struct ShapePair {
    std::int32_t node;
    Vec3 normal;
    double offset;  // surface: dot(normal, y) = offset
  };
  struct SelfPair {
    std::int32_t node, tri;
    double side;  // +1 / -1: which side of the triangle the node stays on
  };

  void detect_self_rt(std::span<const Vec3> x, double margin_mm) noexcept;
  [[nodiscard]] std::uint32_t cell_hash(int cx, int cy, int cz) const noexcept;

  const Topology* topo_ = nullptr;
  double half_thickness_ = 0.5, thickness_ = 1.0, friction_ = 0.5;
  bool self_enabled_ = true;
  std::vector<ShapePair> shape_pairs_;
  int n_shape_ = 0;
  std::vector<SelfPair> self_pairs_;
  int n_self_ = 0;
  // Spatial hash of triangles: counting sort into buckets (cell size ~ node spacing).
  double cell_mm_ = 20.0;
  std::uint32_t bucket_mask_ = 0;
  std::vector<std::uint32_t> bucket_start_;  // size buckets + 1
  std::vector<std::int32_t> bucket_items_;
  std::vector<std::uint32_t> tri_cells_;     // per triangle: hashed cells (up to kCellsPerTri)
  std::vector<std::uint8_t> tri_cell_count_;
  std::vector<std::uint32_t> node_cell_;    // hash bucket of each node
  std::vector<std::int32_t> node_ijk_;      // integer cell of each node (3 per node)
  ContactStats stats_;
  static constexpr int kCellsPerTri = 8;
  static constexpr int kSelfSkipCells = 2;
};

}  // namespace crease::sheet
