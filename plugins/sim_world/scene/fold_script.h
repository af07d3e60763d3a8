// Analytic fold script: exact sheet geometry for tests and the simulated world (no physics).
// A fold rotates the part of the sheet on one side of a crease line (sheet coordinates) by
// theta(t) about that line's current world position; folds compose in order, so a later
// fold carries the layers an earlier one stacked. theta(t) is piecewise linear in keyframes.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "plugins/sheet_model/sheet_params.h"
#include "plugins/sheet_model/vec3.h"

namespace crease::sheet {

struct FoldKey {
  double t_s = 0;
  double theta_deg = 0;
};

struct Fold {
  Vec2 a, b;                    // crease line through these sheet points (on the fixed side's layer)
  Vec2 moving;                  // any sheet point on the side that rotates
  double lift_mm = 0;           // axis offset from the crease's mid-surface towards the flap
                                // (half a thickness per layer below the stack's top)
  std::array<FoldKey, 8> keys{};
  int key_count = 0;
  [[nodiscard]] double theta_deg(double t_s) const noexcept;
};

class FoldScript {
 public:
  // grid: the sheet's size, origin and thickness (layers stack thickness_mm apart).
  explicit FoldScript(const GridParams& grid) : grid_(grid) {}

  FoldScript& add(const Fold& f) {
    folds_.push_back(f);
    return *this;
  }
  [[nodiscard]] double duration_s() const noexcept;
  // World position of sheet point p at time t. RT (no allocation).
  [[nodiscard]] Vec3 position(Vec2 p, double t_s) const noexcept;
  // Positions of every node of a W x H grid (row by row) at time t.
  void node_positions(double t_s, std::span<Vec3> out) const noexcept;
  [[nodiscard]] std::span<const Fold> folds() const noexcept { return folds_; }
  [[nodiscard]] const GridParams& grid() const noexcept { return grid_; }

  // The sequences of the issue. half: top half (v < h/2) over the middle line, 0 -> 175 deg in
  // 5 s, hold 3 s. diagonal: the top-right corner beyond the 45 deg line from (w/2, 0)
  // to (w, w/2) folded 0 -> 170 deg in 4 s, hold 2 s. two_folds: the half fold to 180 deg (5 s, hold 1 s),
  // then the right half of the stack over u = w/2 to 180 deg (5 s, hold 1 s).
  // unfold: the half fold to 175 deg (5 s), hold 1 s, back to 0 in 5 s, hold 1 s.
  static FoldScript half_fold(const GridParams& g);
  static FoldScript diagonal_fold(const GridParams& g);
  static FoldScript two_folds(const GridParams& g);
  static FoldScript unfold(const GridParams& g);

 private:
  [[nodiscard]] Vec3 position_after(Vec2 p, std::size_t n, double t_s) const noexcept;

  GridParams grid_;
  std::vector<Fold> folds_;
};

}  // namespace crease::sheet
