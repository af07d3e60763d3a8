// Plugin `sheet_model` (model loop, 60 Hz by default): the sheet model of seed 000/001 kept
// on the observed sheet.
//   in:  keypoints (latest, Keypoints), target_points (latest, TargetPoints),
//        depth_targets (latest, DepthTargets: the depth path's point-to-plane springs),
//        crease (queue, SheetCreaseEvent), memorize (queue, SheetMemorizeEvent),
//        reset (queue, SheetResetEvent)
//   out: sheet_state (latest, SheetState)
// A step that leaves the state non-finite is rolled back to the state it started from
// (positions and link state) and the update returns degraded (counted in
// sheet_state.rollbacks).
// Parameters (all optional): nodes_u, nodes_v, width_mm, height_mm, density_g_per_m2,
// thickness_mm, origin_x_mm, origin_y_mm, origin_z_mm, turn_deg, substeps,
// coupling (how the key-points pull the model: `springs` (default), seed 001's zero-length
// springs of compliance target_compliance_m_per_n; or `keypoints`, seed 000's node-velocity
// P-controller of gain keypoint_gain_per_s), keypoint_gain_per_s, target_compliance_m_per_n,
// compliance_bending_m_per_n, damping_per_s, yield_strain and plasticity_rate (seed 001's
// elasto-plastic bending links: how the model holds a fold nobody announced; defaults in
// sheet_params.h), crease_strain (a crease inferred from the strain; 0: off), table_height_mm,
// self_collision (0/1), self_collision_every (1..100 substeps; the last substep always),
// predict_unseen_s (how long a key-point is still predicted after it was last seen),
// bound_predictions (0/1: unseen key-points kept within their sheet distance of the seen),
// unseen_speed_memory_s (nodes no key-point pulls move no faster than the fastest key-point
// seen within this many seconds; 0: off),
// depth_compliance_m_per_n (a depth target of weight 1), depth_along_normal (default true: depth
// targets pull along the model's normal only; false: 3-D springs), depth_predict (default false:
// a depth target moves on at its node's velocity between the last two depth frames),
// depth_tangential_weight (0.3: the share of the tangential error a depth target corrects),
// depth_surface_normal (default true: a depth target pulls along the bisector of the model's
// normal and the observed surface's, estimated from the targets of its grid neighbours),
// depth_hold_hidden_mm (1.5: paper under a laid flap that no depth target pulls keeps its place
// on the table; 0: off).

#include <memory>
#include <string>

#include "core/plugin.h"
#include "core/port_types/depth_targets.h"
#include "core/port_types/keypoints.h"
#include "core/port_types/sheet_state.h"
#include "plugins/sheet_model/sheet_runner.h"

namespace {

using namespace crease;

const SheetState kSafeState{};  // zero nodes: readers see "no sheet"

class SheetModelPlugin final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    sheet::SheetParams sp;
    sp.grid.nodes_u = p.get_in_range<int>("nodes_u", 15, 2, 64);
    sp.grid.nodes_v = p.get_in_range<int>("nodes_v", 21, 2, 64);
    sp.grid.width_mm = p.get_in_range<double>("width_mm", 210.0, 10.0, 2000.0);
    sp.grid.height_mm = p.get_in_range<double>("height_mm", 297.0, 10.0, 2000.0);
    sp.grid.areal_density_g_per_m2 = p.get_in_range<double>("density_g_per_m2", 80.0, 1.0, 1000.0);
    sp.grid.thickness_mm = p.get_in_range<double>("thickness_mm", 1.0, 0.01, 20.0);
    // World position of sheet point (0,0) when flat (u -> +x, v -> -y).
    sp.grid.origin_mm = {p.get<double>("origin_x_mm", 0.0), p.get<double>("origin_y_mm", sp.grid.height_mm),
                         p.get<double>("origin_z_mm", 0.5 * sp.grid.thickness_mm)};
    sp.grid.turn_deg = p.get_in_range<double>("turn_deg", 0.0, -180.0, 180.0);  // about z through point (0,0)
    sp.solver.substeps = p.get_in_range<int>("substeps", 10, 1, 100);
    const std::string coupling = p.get<std::string>("coupling", "springs");
    if (!sheet::parse_coupling(coupling, sp.solver.coupling))
      p.fail("coupling", "must be springs or keypoints, not '" + coupling + "'");
    sp.solver.keypoint_gain_per_s = p.get_in_range<double>("keypoint_gain_per_s", 10.0, 0.0, 1e6);
    sp.solver.target_compliance_m_per_n = p.get_in_range<double>("target_compliance_m_per_n", 1e-6, 0.0, 1e3);
    sp.solver.depth_compliance_m_per_n = p.get_in_range<double>("depth_compliance_m_per_n", 0.05, 0.0, 1e6);
    sp.solver.depth_along_normal = p.get<bool>("depth_along_normal", true);
    sp.solver.depth_tangential_weight = p.get_in_range<double>("depth_tangential_weight", 0.3, 0.0, 1.0);
    sp.solver.depth_surface_normal = p.get<bool>("depth_surface_normal", true);
    sp.solver.depth_hold_hidden_mm =
        p.get_in_range<double>("depth_hold_hidden_mm", 1.5, 0.0, 100.0);
    sp.solver.compliance_bending_m_per_n = p.get_in_range<double>("compliance_bending_m_per_n", 0.05, 0.0, 1e3);
    sp.solver.damping_per_s = p.get_in_range<double>("damping_per_s", 1.0, 0.0, 100.0);
    sp.solver.yield_strain = p.get_in_range<double>("yield_strain", sp.solver.yield_strain, 0.0, 1.0);
    sp.solver.plasticity_rate = p.get_in_range<double>("plasticity_rate", sp.solver.plasticity_rate, 0.0, 0.99);
    sp.solver.crease_strain = p.get_in_range<double>("crease_strain", sp.solver.crease_strain, 0.0, 10.0);
    sp.predictor.max_extrapolate_s = p.get_in_range<double>("predict_unseen_s", sp.predictor.max_extrapolate_s, 0.0, 10.0);
    sp.predictor.unseen_speed_memory_s =
        p.get_in_range<double>("unseen_speed_memory_s", sp.predictor.unseen_speed_memory_s, 0.0, 1e3);
    sp.predictor.bound_by_sheet = p.get_in_range<int>("bound_predictions", 1, 0, 1) != 0;
    sp.solver.self_collision = p.get_in_range<int>("self_collision", 1, 0, 1) != 0;
    // Layer contacts enforced every this many substeps (and always on the last one).
    sp.solver.self_collision_every = p.get_in_range<int>("self_collision_every", 2, 1, 100);
    const double table = p.get_in_range<double>("table_height_mm", 0.0, -1e4, 1e4);
    runner_ = std::make_unique<sheet::SheetRunner>(sp, table);
    runner_->set_depth_prediction(p.get<bool>("depth_predict", false));
    state_ = std::make_unique<SheetState>();
    keypoints_ = ports.latest_input<Keypoints>("keypoints");
    targets_ = ports.latest_input<TargetPoints>("target_points");
    depth_ = ports.latest_input<DepthTargets>("depth_targets");
    crease_ = ports.queue_input<SheetCreaseEvent>("crease");
    memorize_ = ports.queue_input<SheetMemorizeEvent>("memorize");
    reset_ = ports.queue_input<SheetResetEvent>("reset");
    out_ = ports.latest_output<SheetState>("sheet_state", kSafeState);
  }

  Status update(const Cycle& cycle) override {
    if (keypoints_.bound() && keypoints_.poll().is_new()) runner_->observe_keypoints(keypoints_.value());
    if (targets_.bound() && targets_.poll().is_new()) runner_->set_targets(targets_.value());
    if (depth_.bound() && depth_.poll().is_new()) runner_->set_depth_targets(depth_.value());
    SheetResetEvent r;
    while (reset_.bound() && reset_.try_pop(r)) runner_->apply(r);
    SheetCreaseEvent c;
    while (crease_.bound() && crease_.try_pop(c)) runner_->apply(c);
    SheetMemorizeEvent m;
    while (memorize_.bound() && memorize_.try_pop(m)) runner_->apply(m);
    const double dt = cycle.period_ns > 0 ? static_cast<double>(cycle.period_ns) * 1e-9 : 1.0 / 60;
    const bool ok = runner_->step_rt(dt, cycle.time_ns, *state_);
    out_.write(*state_, cycle.time_ns);
    return ok ? Status::ok : Status::degraded;
  }

  void activate() override { runner_->apply(SheetResetEvent{}); }

 private:
  std::unique_ptr<sheet::SheetRunner> runner_;
  std::unique_ptr<SheetState> state_;
  LatestInput<Keypoints> keypoints_;
  LatestInput<TargetPoints> targets_;
  LatestInput<DepthTargets> depth_;
  QueueInput<SheetCreaseEvent> crease_;
  QueueInput<SheetMemorizeEvent> memorize_;
  QueueInput<SheetResetEvent> reset_;
  LatestOutput<SheetState> out_;
};

}  // namespace

CREASE_PLUGIN(SheetModelPlugin, "sheet_model", "0.1.0")
