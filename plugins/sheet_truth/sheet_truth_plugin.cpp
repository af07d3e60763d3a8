// Plugin `sheet_truth` (model loop): an analytic sheet for the tracking benchmarks and tests —
// the analytic fold script of plugins/sheet_model (exact geometry, no physics) played from
// activation. Writes `sheet_truth` (latest, SheetState: positions and normals; no strain).
// Parameters: fold (half | diagonal | two_folds | unfold), start_s (delay before the fold),
// repeat (restart after the script ends), origin_x_mm / origin_y_mm / origin_z_mm (world
// position of sheet point (0,0) when flat; default: the sheet centred on the world origin,
// where the calibrated cameras look), nodes_u, nodes_v.
// It tells the tracking model nothing: no crease, no fold line (the robot has no such oracle;
// only its folding sequence knows the crease it intends, and only roughly). The model holds a
// fold it was not told of by itself (plugins/sheet_model/README.md, "A fold nobody announced").
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/plugin.h"
#include "core/port_types/sheet_state.h"
#include "plugins/sim_world/scene/fold_script.h"

namespace {

using namespace crease;

class SheetTruth final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    sheet::GridParams g;
    g.nodes_u = p.get_in_range<int>("nodes_u", 15, 2, 64);
    g.nodes_v = p.get_in_range<int>("nodes_v", 21, 2, 64);
    g.origin_mm = {p.get<double>("origin_x_mm", -0.5 * g.width_mm), p.get<double>("origin_y_mm", 0.5 * g.height_mm),
                   p.get<double>("origin_z_mm", 0.5 * g.thickness_mm)};
    const std::string fold = p.get<std::string>("fold", "half");
    if (fold == "half") script_ = sheet::FoldScript::half_fold(g);
    else if (fold == "diagonal") script_ = sheet::FoldScript::diagonal_fold(g);
    else if (fold == "two_folds") script_ = sheet::FoldScript::two_folds(g);
    else if (fold == "unfold") script_ = sheet::FoldScript::unfold(g);
    else p.fail("fold", "must be half, diagonal, two_folds or unfold, not '" + fold + "'");
    start_s_ = p.get_in_range<double>("start_s", 1.0, 0.0, 1e6);
    repeat_ = p.get<bool>("repeat", false);
    grid_ = g;
    nodes_.resize(static_cast<std::size_t>(g.nodes_u) * g.nodes_v);
    state_ = std::make_unique<SheetState>();
    state_->nodes_u = static_cast<std::uint16_t>(g.nodes_u);
    state_->nodes_v = static_cast<std::uint16_t>(g.nodes_v);
    state_->width_mm = static_cast<float>(g.width_mm);
    state_->height_mm = static_cast<float>(g.height_mm);
    out_ = ports.latest_output<SheetState>("sheet_truth", SheetState{});
  }

  void activate() override { t0_ns_ = -1; }

  Status update(const Cycle& cycle) override {
    if (t0_ns_ < 0) t0_ns_ = cycle.time_ns;
    double t = double(cycle.time_ns - t0_ns_) * 1e-9 - start_s_;
    if (repeat_ && t > script_.duration_s()) {
      const double lap = script_.duration_s() + start_s_;
      t = std::fmod(t + start_s_, lap) - start_s_;  // starting over: the sheet is flat again
    }
    script_.node_positions(t < 0 ? 0.0 : t, nodes_);
    const int W = grid_.nodes_u, H = grid_.nodes_v;
    for (int j = 0; j < H; ++j) {
      for (int i = 0; i < W; ++i) {
        const std::size_t k = static_cast<std::size_t>(j) * W + i;
        const sheet::Vec3& x = nodes_[k];
        state_->position_mm[k][0] = float(x.x);
        state_->position_mm[k][1] = float(x.y);
        state_->position_mm[k][2] = float(x.z);
        // Printed-face normal: -(du x dv) by central differences (z = u x v points into the paper).
        const sheet::Vec3 du = nodes_[j * W + std::min(i + 1, W - 1)] - nodes_[j * W + std::max(i - 1, 0)];
        const sheet::Vec3 dv = nodes_[std::min(j + 1, H - 1) * W + i] - nodes_[std::max(j - 1, 0) * W + i];
        const double nx = -(du.y * dv.z - du.z * dv.y), ny = -(du.z * dv.x - du.x * dv.z), nz = -(du.x * dv.y - du.y * dv.x);
        const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
        const double inv = len > 0 ? 1.0 / len : 0.0;
        state_->normal[k][0] = float(nx * inv);
        state_->normal[k][1] = float(ny * inv);
        state_->normal[k][2] = float(nz * inv);
      }
    }
    state_->timestamp_ns = cycle.time_ns;
    state_->step++;
    out_.write(*state_, cycle.time_ns);
    return Status::ok;
  }

 private:
  sheet::GridParams grid_;
  sheet::FoldScript script_ = sheet::FoldScript::half_fold(sheet::GridParams{});
  std::vector<sheet::Vec3> nodes_;
  std::unique_ptr<SheetState> state_;
  LatestOutput<SheetState> out_;
  double start_s_ = 1.0;
  bool repeat_ = false;
  std::int64_t t0_ns_ = -1;
};

}  // namespace

CREASE_PLUGIN(SheetTruth, "sheet_truth", "1.0.0")
