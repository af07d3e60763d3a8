// Plugin `sheet_truth` (model loop): an analytic sheet for the tracking benchmarks and tests —
// the analytic fold script of plugins/sheet_model (exact geometry, no physics) played from
// activation. Writes `sheet_truth` (latest, SheetState: positions and normals; no strain).
// Parameters: fold (half | diagonal | two_folds | unfold), start_s (delay before the fold),
// repeat (restart after the script ends), origin_x_mm / origin_y_mm / origin_z_mm (world
// position of sheet point (0,0) when flat; default: the sheet centred on the world origin,
// where the calibrated cameras look), nodes_u, nodes_v, announce_creases (default true).
// With announce_creases it also plays the folding sequence's part towards the model: when a
// fold starts it pushes a crease `add` along the fold line on the `crease` queue (the
// sequence knows where it folds), and a `clear` when a repeat starts over.
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
    if (p.get<bool>("announce_creases", true)) creases_ = ports.queue_output<SheetCreaseEvent>("crease");
    announced_.assign(script_.folds().size(), false);
  }

  void activate() override { t0_ns_ = -1; }

  Status update(const Cycle& cycle) override {
    if (t0_ns_ < 0) t0_ns_ = cycle.time_ns;
    double t = double(cycle.time_ns - t0_ns_) * 1e-9 - start_s_;
    if (repeat_ && t > script_.duration_s()) {
      const double lap = script_.duration_s() + start_s_;
      const auto laps = static_cast<std::int64_t>((t + start_s_) / lap);
      if (laps != laps_) {  // starting over: the sheet is flat again
        laps_ = laps;
        std::fill(announced_.begin(), announced_.end(), false);
        SheetCreaseEvent clear;
        clear.op = SheetCreaseEvent::Op::clear;
        clear.timestamp_ns = cycle.time_ns;
        if (creases_.bound()) (void)creases_.try_push(clear);
      }
      t = std::fmod(t + start_s_, lap) - start_s_;
    }
    announce_creases(t < 0 ? 0.0 : t, cycle.time_ns);
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
  // Pushes a crease along each fold line whose fold has begun (theta > 0), once per lap.
  void announce_creases(double t, std::int64_t now_ns) noexcept {
    if (!creases_.bound()) return;
    const auto folds = script_.folds();
    for (std::size_t f = 0; f < folds.size(); ++f) {
      if (announced_[f] || folds[f].theta_deg(t) <= 0.0) continue;
      const sheet::Vec2 a = folds[f].a, b = folds[f].b;
      const double dx = b.u - a.u, dy = b.v - a.v, len = std::sqrt(dx * dx + dy * dy);
      if (len <= 0) continue;
      const double ext = 2.0 * (grid_.width_mm + grid_.height_mm) / len;  // beyond the sheet on both sides
      SheetCreaseEvent e;
      e.op = SheetCreaseEvent::Op::add;
      e.timestamp_ns = now_ns;
      e.a_mm[0] = float(a.u - ext * dx);
      e.a_mm[1] = float(a.v - ext * dy);
      e.b_mm[0] = float(b.u + ext * dx);
      e.b_mm[1] = float(b.v + ext * dy);
      announced_[f] = creases_.try_push(e);
    }
  }

  sheet::GridParams grid_;
  sheet::FoldScript script_ = sheet::FoldScript::half_fold(sheet::GridParams{});
  std::vector<sheet::Vec3> nodes_;
  std::unique_ptr<SheetState> state_;
  LatestOutput<SheetState> out_;
  QueueOutput<SheetCreaseEvent> creases_;
  std::vector<bool> announced_;  // per fold, this lap (sized at configure)
  std::int64_t laps_ = 0;
  double start_s_ = 1.0;
  bool repeat_ = false;
  std::int64_t t0_ns_ = -1;
};

}  // namespace

CREASE_PLUGIN(SheetTruth, "sheet_truth", "1.0.0")
