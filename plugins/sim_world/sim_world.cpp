#include "plugins/sim_world/sim_world.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/errors.h"
#include "plugins/sheet_model/sheet_state_writer.h"
#include "plugins/sim_world/table_contact.h"

namespace crease::world {
namespace {

void require(bool ok, const char* key, const char* why) {
  if (!ok) throw std::invalid_argument(std::string("sim_world: ") + key + ": " + why);
}

// A hand shape this far above the table still enters the balance: a finger deflected by what
// it touched springs back up to the joint limits' reach (~30 mm at a fingertip) if that goes.
constexpr double kTableGapMm = 50.0;
// The most a hand joint's deflection changes in one step (rad; 50 rad/s, far beyond the drives'
// 2 rad/s): the balance's contacts are linear about the step's pose, and a stiff shell's gap
// predicted to close by a large turn flung the hand about step after step.
constexpr double kMaxDeflectionStepRad = 0.05;

bool finite_all(const World::HandJoints& a) {
  for (double v : a)
    if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace

World::World(const robot::RobotModel& model, const WorldParams& params) : params_(params) {
  require(params_.dt_s > 0 && params_.dt_s <= 0.1, "dt_s", "must be in (0, 0.1] s");
  require(params_.table_contact_area_mm2 > 0, "table_contact_area_mm2", "must be > 0");
  require(params_.initial_stiffness_nm_per_rad >= 0, "initial_stiffness_nm_per_rad", "must be >= 0");
  draws_ = draw_world(params_, model.params());

  sheet::SheetParams sp = params_.sheet;
  sp.solver.compliance_structural_m_per_n /= draws_.stiffness_scale;
  sp.solver.compliance_bending_m_per_n /= draws_.stiffness_scale;
  sp.solver.yield_strain *= draws_.yield_scale;
  sp.solver.friction = params_.table_friction ? draws_.paper_table : 0.0;  // the sheet's own table contact
  sp.solver.layer_friction = params_.layer_friction ? draws_.paper_paper : 0.0;
  sp.grid.origin_mm.z = params_.table_height_mm + 0.5 * sp.grid.thickness_mm;
  sheet_ = std::make_unique<sheet::XpbdSheet>(sp);
  {
    const auto& e = params_.table_extent_mm;
    require(e[0] < e[1] && e[2] < e[3], "table_extent_mm", "must be {x_min, x_max, y_min, y_max}, min < max");
    if (e[0] <= -WorldParams::kNoEdge && e[1] >= WorldParams::kNoEdge && e[2] <= -WorldParams::kNoEdge &&
        e[3] >= WorldParams::kNoEdge) {
      table_.add_table(params_.table_height_mm);
    } else {
      add_table_slab();
    }
  }
  sheet_->set_collision_world(&table_);

  // The sheet's pose: the flat sheet turned about its centre by the yaw, then shifted.
  {
    const auto flat = sheet_->positions();
    std::vector<Vec3> x(flat.begin(), flat.end());
    const sheet::Grid& g = sheet_->grid();
    const Vec3 c = sheet_->flat_position({0.5 * g.width_mm, 0.5 * g.height_mm});
    const double a = draws_.sheet_yaw_deg * std::numbers::pi / 180.0, ca = std::cos(a), sa = std::sin(a);
    for (Vec3& p : x) {
      const Vec3 d = p - c;
      p = {c.x + ca * d.x - sa * d.y + draws_.sheet_dx_mm, c.y + sa * d.x + ca * d.y + draws_.sheet_dy_mm, p.z};
    }
    sheet_->set_positions(x);
  }

  std::array<HandCompliance::Limits, robot::kSides> hand_limits{};  // the balances', configured below
  for (int s = 0; s < robot::kSides; ++s) {
    const Side side = static_cast<Side>(s);
    kin_[s] = std::make_unique<SideKinematics>(model, side);
    kin_view_[s] = kin_[s].get();
    HandSim& h = hand_[s];
    const auto& arm = model.arm_joints(side);
    const auto& hand = model.hand_joints(side);
    HandCompliance::Limits lim;
    for (int j = 0; j < robot::kArmJoints; ++j) {
      h.arm_lo[j] = arm[j].lower_rad;
      h.arm_hi[j] = arm[j].upper_rad;
      h.arm_vmax[j] = arm[j].velocity_rad_s;
      h.arm[j] = h.arm_cmd[j] = std::clamp(params_.initial_arm_rad[s][j], h.arm_lo[j], h.arm_hi[j]);
    }
    for (int j = 0; j < robot::kHandJoints; ++j) {
      h.hand_lo[j] = lim.lower_rad[j] = hand[j].lower_rad;
      h.hand_hi[j] = lim.upper_rad[j] = hand[j].upper_rad;
      h.hand_vmax[j] = hand[j].velocity_rad_s;
      lim.effort_nm[j] = hand[j].effort_nm > 0 ? hand[j].effort_nm : 1e9;
      h.target[j] = h.target_cmd[j] = h.angles[j] =
          std::clamp(params_.initial_hand_rad[s][j], h.hand_lo[j], h.hand_hi[j]);
      h.stiffness[j] = h.stiffness_cmd[j] = params_.initial_stiffness_nm_per_rad;
    }
    compliance_[s] = std::make_unique<HandCompliance>();
    hand_limits[s] = lim;  // configured once the contacts' worst case is known
    const std::string& prefix = model.params().side(side).prefix;
    for (int f = 0; f < robot::kFingertips; ++f) {
      h.tip_link[f] = kin_[s]->link_index(prefix + std::string(robot::kFingertipNames[f]) + "pad");
      if (h.tip_link[f] < 0) throw ConfigError(model.urdf_file() + ": no link " + prefix + std::string(robot::kFingertipNames[f]) + "pad");
    }
    kin_[s]->update_rt(h.arm, h.angles);
  }
  shapes_ = build_robot_shapes(model, kin_view_, draws_, params_);

  FingerContacts::Config cfg;
  cfg.table_height_mm = params_.table_height_mm;
  for (int k = 0; k < 4; ++k) cfg.table_extent_mm[k] = params_.table_extent_mm[k];
  cfg.table_friction = draws_.paper_table;
  cfg.layer_friction = params_.layer_friction ? draws_.paper_paper : 0.0;
  cfg.hand_contacts = params_.hand_contacts;
  cfg.finger_friction = params_.finger_friction;
  cfg.table_friction_on = params_.table_friction;
  contacts_.configure(*sheet_, shapes_, cfg);
  thumb_contacts_.configure(shapes_, params_.table_contact_area_mm2);
  pose_pre_.resize(shapes_.size());
  pose_target_.resize(shapes_.size());
  sheet_->set_substep_contacts(&contacts_);

  for (int s = 0; s < robot::kSides; ++s) {
    const std::size_t cap =
        static_cast<std::size_t>(sheet_->node_count()) * FingerContacts::kMaxShapesPerNode +
        shapes_.size() + static_cast<std::size_t>(thumb_contacts_.pairs(s));
    hand_contacts_[s].resize(cap);
    hand_contact_shape_[s].resize(cap);
    hand_contact_shape2_[s].resize(cap);
    hand_contact_force_[s].resize(cap);
    compliance_[s]->configure(hand_limits[s], static_cast<int>(cap));
    compliance_[s]->set_max_step_rad(kMaxDeflectionStepRad);
  }
  shape_normal_n_.assign(shapes_.size(), 0.0);
  shape_normal_vec_n_.assign(shapes_.size(), Vec3{});
  last_good_.assign(sheet_->positions().begin(), sheet_->positions().end());
  normals_.resize(sheet_->node_count());
  strain_.resize(sheet_->link_count());
  fill_state_rt();
}

void World::command_arm_rt(Side s, std::span<const double, robot::kArmJoints> q) noexcept {
  HandSim& h = hand_[index(s)];
  for (int j = 0; j < robot::kArmJoints; ++j) {
    if (!std::isfinite(q[j])) {
      ++state_.refused_targets;
      continue;
    }
    const double c = std::clamp(q[j], h.arm_lo[j], h.arm_hi[j]);
    if (c != q[j]) ++state_.clamped_targets;
    h.arm_cmd[j] = c;
  }
}

void World::command_hand_rt(Side s, std::span<const double, robot::kHandJoints> target,
                            std::span<const double, robot::kHandJoints> stiffness) noexcept {
  HandSim& h = hand_[index(s)];
  for (int j = 0; j < robot::kHandJoints; ++j) {
    if (!std::isfinite(target[j])) {
      ++state_.refused_targets;
    } else {
      const double c = std::clamp(target[j], h.hand_lo[j], h.hand_hi[j]);
      if (c != target[j]) ++state_.clamped_targets;
      h.target_cmd[j] = c;
    }
    if (!(std::isfinite(stiffness[j]) && stiffness[j] >= 0)) {
      ++state_.refused_stiffness;
    } else {
      h.stiffness_cmd[j] = stiffness[j];
    }
  }
}

void World::apply_commands_rt(HandSim& h) noexcept {
  // The drives move no joint faster than its URDF velocity limit.
  bool slowed = false;
  for (int j = 0; j < robot::kArmJoints; ++j) {
    const double step = h.arm_vmax[j] * params_.dt_s;
    const double d = std::clamp(h.arm_cmd[j] - h.arm[j], -step, step);
    slowed = slowed || d != h.arm_cmd[j] - h.arm[j];
    h.arm[j] += d;
  }
  for (int j = 0; j < robot::kHandJoints; ++j) {
    const double step = h.hand_vmax[j] * params_.dt_s;
    const double d = std::clamp(h.target_cmd[j] - h.target[j], -step, step);
    slowed = slowed || d != h.target_cmd[j] - h.target[j];
    h.target[j] += d;
    h.stiffness[j] = h.stiffness_cmd[j];
  }
  if (slowed) ++state_.rate_limited;
}

void World::pose_hands_rt() noexcept {
  for (int s = 0; s < robot::kSides; ++s) {
    HandSim& h = hand_[s];
    for (int j = 0; j < robot::kHandJoints; ++j)
      h.angles[j] = std::clamp(h.target[j] + h.deflection[j], h.hand_lo[j], h.hand_hi[j]);
    kin_[s]->update_rt(h.arm, h.angles);
  }
}

// The table with edges, for the sheet: a slab 50 mm deep under the top (wider ranges are cut to
// 2 m) whose edges are rounded (table_edge_radius_mm): a box up to the rounding's centre line, a
// box of the top's thickness inset by the radius at each edge, and a capsule along each edge. A
// square edge caught the sheet: a node of paper hanging over it, pulled back, met the edge's side
// face square on and stuck there while the rest was dragged over it (the sheet stretched 74 %,
// moved 3 of the finger's 40 mm); round, the pull slides it up over the edge.
void World::add_table_slab() {
  const auto& e = params_.table_extent_mm;
  const double h = params_.table_height_mm, r = params_.table_edge_radius_mm;
  const double x0 = std::max(e[0], -1000.0), x1 = std::min(e[1], 1000.0);
  const double y0 = std::max(e[2], -1000.0), y1 = std::min(e[3], 1000.0);
  const auto has_edge = [](double v) { return std::fabs(v) < WorldParams::kNoEdge; };
  const bool edge[4] = {has_edge(e[0]), has_edge(e[1]), has_edge(e[2]), has_edge(e[3])};
  if (!(r > 0)) {
    table_.add_box({x1 - x0, y1 - y0, 50.0}, {0.5 * (x0 + x1), 0.5 * (y0 + y1), h - 25.0});
    return;
  }
  require(2.0 * r < std::min(x1 - x0, y1 - y0) && r < 25.0, "table_edge_radius_mm",
          "must be under 25 mm and half the table");
  table_.add_box({x1 - x0, y1 - y0, 50.0 - r},
                 {0.5 * (x0 + x1), 0.5 * (y0 + y1), h - r - 0.5 * (50.0 - r)});
  // The top: inset by the radius where there is an edge.
  const double tx0 = edge[0] ? x0 + r : x0, tx1 = edge[1] ? x1 - r : x1;
  const double ty0 = edge[2] ? y0 + r : y0, ty1 = edge[3] ? y1 - r : y1;
  table_.add_box({tx1 - tx0, ty1 - ty0, r}, {0.5 * (tx0 + tx1), 0.5 * (ty0 + ty1), h - 0.5 * r});
  // A capsule along each edge (ODE's capsule axis is its z): its caps round the corners.
  const double along_x[9] = {0, 0, 1, 0, 1, 0, -1, 0, 0};  // capsule z -> world x
  const double along_y[9] = {1, 0, 0, 0, 0, 1, 0, -1, 0};  // capsule z -> world y
  for (int k = 0; k < 4; ++k) {
    if (!edge[k]) continue;
    const bool runs_along_y = k < 2;  // x = x0 or x1; else y = y0 or y1, along x
    const Vec3 c = runs_along_y ? Vec3{k == 0 ? x0 + r : x1 - r, 0.5 * (ty0 + ty1), h - r}
                                : Vec3{0.5 * (tx0 + tx1), k == 2 ? y0 + r : y1 - r, h - r};
    const int id = table_.add_capsule(r, runs_along_y ? ty1 - ty0 : tx1 - tx0, c);
    table_.set_pose(id, c, runs_along_y ? along_y : along_x);
  }
}

void World::step_rt() noexcept {
  for (HandSim& h : hand_) apply_commands_rt(h);
  // Where the shapes would be at the commanded targets themselves: how far each may spring
  // back if what holds it goes (the contacts' candidates must reach that far).
  for (int s = 0; s < robot::kSides; ++s) kin_[s]->update_rt(hand_[s].arm, hand_[s].target);
  for (std::size_t k = 0; k < shapes_.size(); ++k)
    pose_target_[k] = kin_[shapes_[k].side]->compose(shapes_[k].link, shapes_[k].link_from_shape);
  // Where the new commands put the shapes with the last deflection; the hands settle there
  // against the sheet as the last step left it, and the table.
  pose_hands_rt();
  for (std::size_t k = 0; k < shapes_.size(); ++k)
    pose_pre_[k] = kin_[shapes_[k].side]->compose(shapes_[k].link, shapes_[k].link_from_shape);
  const std::array<HandJoints, robot::kSides> saved{hand_[0].deflection, hand_[1].deflection};
  contacts_.measure_rt(pose_pre_, sheet_->positions());
  for (int s = 0; s < robot::kSides; ++s) settle_hand_rt(s);
  bool ok = finite_all(hand_[0].deflection) && finite_all(hand_[1].deflection);
  if (!ok) {
    for (int s = 0; s < robot::kSides; ++s) hand_[s].deflection = saved[s];
  }
  pose_hands_rt();
  advance_shape_poses_rt(shapes_, kin_view_, false);
  for (std::size_t k = 0; k < shapes_.size(); ++k) {
    const WorldShape& sh = shapes_[k];
    double extent = 0;
    for (int a = 0; a < 3; ++a) extent = std::max(extent, half_extent(sh.geom, sh.pose1, a));
    double c = 0;  // |rotation between the two poses| ~ 2 sin(angle / 2) from the columns
    for (int a = 0; a < 3; ++a) c = std::max(c, sheet::norm(sh.pose1.axis(a) - pose_target_[k].axis(a)));
    contacts_.set_springback(static_cast<int>(k), sheet::norm(sh.pose1.t - pose_target_[k].t) + 1.7320508075688772 * extent * c);
  }

  const auto x0 = sheet_->positions();
  std::copy(x0.begin(), x0.end(), last_good_.begin());
  sheet_->save_links_rt();
  contacts_.begin_step_rt(x0, sheet_->velocities(), params_.dt_s);
  sheet_->step_rt(params_.dt_s);
  ok = ok && sheet_->state_finite() && !poison_;
  if (ok) {
    contacts_.end_step_rt(sheet_->positions());
    measure_penetration_rt();
  } else {
    poison_ = false;
    sheet_->restore_links_rt();
    sheet_->set_positions(last_good_);
    ++state_.rollbacks;
  }
  ++state_.step;
  fill_state_rt();
}

void World::settle_hand_rt(int side) noexcept {
  HandSim& h = hand_[side];
  const SideKinematics& kin = *kin_[side];
  int n = 0;
  auto& contacts = hand_contacts_[side];
  auto& shape_of = hand_contact_shape_[side];
  auto& shape2_of = hand_contact_shape2_[side];
  auto& force = hand_contact_force_[side];
  for (const FingerContacts::Residual& r : contacts_.residuals()) {
    const WorldShape& s = shapes_[r.shape];
    if (s.side != side || !s.compliant) continue;
    contacts[n] = {s.link, r.point, r.normal, r.depth_mm, r.stiffness_n_per_mm, -1, {}, {}};
    if (r.shape2 >= 0 && shapes_[r.shape2].compliant) {
      contacts[n].link2 = shapes_[r.shape2].link;
      contacts[n].point2 = r.point2;
      contacts[n].normal2 = r.normal2;
    }
    shape_of[n] = r.shape;
    shape2_of[n++] = r.shape2;
  }
  // The hand's own shapes on the table.
  for (int k = 0; k < static_cast<int>(shapes_.size()); ++k) {
    const WorldShape& s = shapes_[k];
    if (s.side != side) continue;
    shape_normal_n_[k] = 0;
    shape_normal_vec_n_[k] = Vec3{};
    if (!params_.hand_contacts || !s.compliant) continue;
    const TableContact t = table_contact(s.geom, pose_pre_[k], params_.table_height_mm,
                                         params_.table_extent_mm.data());
    if (!t.over) continue;
    if (t.depth_mm <= -kTableGapMm)
      continue;  // a gap that may close counts too (hand_compliance.h)
    contacts[n] = {s.link,
                   t.point,
                   t.normal,
                   t.depth_mm,
                   s.stiffness_n_per_mm3 * params_.table_contact_area_mm2,
                   -1,
                   {},
                   {}};
    shape_of[n] = k;
    shape2_of[n++] = -1;
  }
  // The thumb against the other fingers.
  if (params_.hand_contacts && params_.thumb_contacts) {
    const std::size_t room = contacts.size() - static_cast<std::size_t>(n);
    n += thumb_contacts_.measure_rt(side, pose_pre_, std::span(contacts.data() + n, room),
                                    std::span(shape_of.data() + n, room),
                                    std::span(shape2_of.data() + n, room));
  }
  // Friction acts on the sheet and is reported per fingertip, but does not bend the joints:
  // fed back explicitly, a Coulomb force that flips with every small slip drives a finger as
  // soft sideways as these (a wrist of 1 N m/rad gives mm under 0.1 N) into a limit cycle.
  compliance_[side]->solve_rt(kin, std::span<const HandCompliance::Contact>(contacts.data(), n), h.target,
                              h.stiffness, h.tau_external, params_.joint_compliance, h.deflection,
                              std::span<double>(force.data(), n));
  for (int c = 0; c < n; ++c) {
    const int k = shape_of[c], k2 = shape2_of[c];
    shape_normal_n_[k] += force[c];
    shape_normal_vec_n_[k] -= force[c] * contacts[c].normal;
    if (k2 >= 0) {
      shape_normal_n_[k2] += force[c];
      shape_normal_vec_n_[k2] -= force[c] * contacts[c].normal2;
    }
  }
  n_settled_[side] = n;
}

double World::geometric_penetration_mm() const noexcept {
  double worst = 0;
  const double h = 0.5 * sheet_->params().grid.thickness_mm;
  const auto x = sheet_->positions();
  for (const WorldShape& s : shapes_) {
    if (!s.compliant) continue;
    const TableContact t =
        table_contact(s.geom, s.pose1, params_.table_height_mm, params_.table_extent_mm.data());
    if (t.over) worst = std::max(worst, t.depth_mm);
    double e[3];
    for (int a = 0; a < 3; ++a) e[a] = half_extent(s.geom, s.pose1, a) + h;
    for (const Vec3& p : x) {
      if (std::fabs(p.x - s.pose1.t.x) > e[0] || std::fabs(p.y - s.pose1.t.y) > e[1] || std::fabs(p.z - s.pose1.t.z) > e[2])
        continue;
      worst = std::max(worst, h - closest_surface(s.geom, s.pose1, p).distance_mm);
    }
  }
  return worst;
}

bool World::over_table(Vec3 p) const noexcept {
  return over_extent(p, params_.table_extent_mm.data());
}

void World::measure_penetration_rt() noexcept {
  double worst = 0;
  for (const FingerContacts::Residual& r : contacts_.residuals()) worst = std::max(worst, r.depth_mm);
  if (params_.hand_contacts) {
    for (const WorldShape& s : shapes_) {
      const TableContact t =
          table_contact(s.geom, s.pose1, params_.table_height_mm, params_.table_extent_mm.data());
      if (t.over) worst = std::max(worst, t.depth_mm);
    }
  }
  max_penetration_mm_ = worst;
}

void World::fill_state_rt() noexcept {
  state_.time_s = static_cast<double>(state_.step) * params_.dt_s;
  state_.timestamp_ns = static_cast<std::int64_t>(std::llround(state_.time_s * 1e9));
  for (int s = 0; s < robot::kSides; ++s) {
    HandSim& h = hand_[s];
    WorldHand& out = state_.hand[s];
    for (int j = 0; j < robot::kHandJoints; ++j) {
      out.joint_rad[j] = static_cast<float>(h.angles[j]);
      out.deflection_rad[j] = static_cast<float>(h.angles[j] - h.target[j]);
    }
    Vec3 tip_force[robot::kFingertips], tip_fric[robot::kFingertips], palm;
    double tip_normal[robot::kFingertips] = {}, under_table = 0;
    bool tip_contact[robot::kFingertips] = {}, palm_contact = false;
    for (int k = 0; k < static_cast<int>(shapes_.size()); ++k) {
      const WorldShape& sh = shapes_[k];
      if (sh.side != s) continue;
      if (sh.role == ShapeRole::arm || sh.role == ShapeRole::hand) {
        const TableContact t = table_contact(sh.geom, sh.pose1, params_.table_height_mm,
                                             params_.table_extent_mm.data());
        if (t.over) under_table = std::max(under_table, t.depth_mm);
      }
      const FingerContacts::ShapeLoad& l = contacts_.load(k);
      const Vec3 f = shape_normal_vec_n_[k] + l.friction_n;
      const bool touching = shape_normal_n_[k] > 0 || l.nodes > 0;
      if (sh.fingertip >= 0) {
        tip_force[sh.fingertip] += f;
        tip_fric[sh.fingertip] += l.friction_n;
        tip_normal[sh.fingertip] += shape_normal_n_[k];
        tip_contact[sh.fingertip] = tip_contact[sh.fingertip] || touching;
      } else if (sh.role == ShapeRole::palm) {
        palm += f;
        palm_contact = palm_contact || touching;
      }
    }
    for (int f = 0; f < robot::kFingertips; ++f) {
      WorldFingertip& t = out.tip[f];
      const Pose& p = kin_[s]->link_pose(h.tip_link[f]);
      t.position_mm[0] = static_cast<float>(p.t.x);
      t.position_mm[1] = static_cast<float>(p.t.y);
      t.position_mm[2] = static_cast<float>(p.t.z);
      for (int e = 0; e < 9; ++e) t.rotation[e] = static_cast<float>(p.r[e]);
      t.force_n[0] = static_cast<float>(tip_force[f].x);
      t.force_n[1] = static_cast<float>(tip_force[f].y);
      t.force_n[2] = static_cast<float>(tip_force[f].z);
      t.normal_force_n = static_cast<float>(tip_normal[f]);
      t.tangential_force_n = static_cast<float>(sheet::norm(tip_fric[f]));
      t.contact = tip_contact[f] ? 1 : 0;
    }
    out.palm_force_n[0] = static_cast<float>(palm.x);
    out.palm_force_n[1] = static_cast<float>(palm.y);
    out.palm_force_n[2] = static_cast<float>(palm.z);
    out.palm_contact = palm_contact ? 1 : 0;
    state_.under_table_mm[s] = static_cast<float>(under_table);
  }
  // Nodes resting on the table (within 0.05 mm of lying on it) and their share of the area.
  const auto x = sheet_->positions();
  const auto m = sheet_->node_masses_kg();
  const double rest_z = params_.table_height_mm + 0.5 * sheet_->params().grid.thickness_mm + 0.05;
  const double mm2_per_kg = 1.0 / (sheet_->params().grid.areal_density_g_per_m2 * 1e-9);
  double area = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (x[i].z <= rest_z && over_table(x[i])) area += m[i] * mm2_per_kg;
  state_.sheet_table_contact_area_mm2 = static_cast<float>(area);
}

void World::export_sheet_rt(SheetState& out) noexcept {
  sheet::write_sheet_state(*sheet_, normals_, strain_, state_.timestamp_ns, state_.step, out);
  out.fit_error_mm = -1.0f;
  out.observations = 0;
  out.rollbacks = state_.rollbacks;
}

}  // namespace crease::world
