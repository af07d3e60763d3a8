#include "plugins/robot_model/arm_ik.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"

namespace crease::robot {

namespace {
using Mat67 = Eigen::Matrix<double, 6, kArmJoints>;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Vec7 = Eigen::Matrix<double, kArmJoints, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
}  // namespace

ArmIk::ArmIk(const RobotModel& model, Side side, const Options& options) : opt_(options) {
  const std::string prefix = model.params().side(side).prefix;
  flange_chain_ = std::make_unique<ToolChain>(model.make_chain(side, prefix + "flange"));
  if (flange_chain_->chain().getNrOfJoints() != static_cast<unsigned>(kArmJoints)) {
    throw ConfigError(model.urdf_file() + ": the world -> " + prefix + "flange chain must hold the arm's 7 joints");
  }
  const auto& sources = flange_chain_->sources();
  for (int j = 0; j < kArmJoints; ++j) {
    if (sources[j].kind != JointSource::arm || sources[j].index != j || sources[j].multiplier != 1.0 ||
        sources[j].offset != 0.0) {
      throw ConfigError(model.urdf_file() + ": the arm's chain must hold S1..W2 in order");
    }
  }
  rt_chain_ = std::make_unique<ArmChainRt>(flange_chain_->chain());
  q_.resize(kArmJoints);
  tools_.reserve(kToolFrames);
  for (int f = 0; f < kToolFrames; ++f) {
    tools_.push_back(model.make_chain(side, prefix + std::string(kToolFrameLinks[f])));
  }
  const auto& joints = model.arm_joints(side);
  for (int j = 0; j < kArmJoints; ++j) {
    lo_[j] = joints[j].lower_rad;
    hi_[j] = joints[j].upper_rad;
    vmax_[j] = joints[j].velocity_rad_s;
    if (!(opt_.rest_rad[j] >= lo_[j] && opt_.rest_rad[j] <= hi_[j])) {
      throw ConfigError("rest posture: joint " + joints[j].name + " outside its limits");
    }
  }
}

bool ArmIk::set_tool(ToolFrame tool, std::span<const double, kArmJoints> arm, HandAngles hand) noexcept {
  KDL::Frame world_flange, world_tool;
  if (!flange_chain_->pose_m(arm, hand, world_flange)) return false;
  if (!tools_[static_cast<int>(tool)].pose_m(arm, hand, world_tool)) return false;
  set_tool_offset(tool, world_flange.Inverse() * world_tool);
  return true;
}

KDL::Frame ArmIk::tool_pose(std::span<const double, kArmJoints> q) noexcept {
  for (int j = 0; j < kArmJoints; ++j) q_(j) = q[j];
  std::array<Eigen::Vector3d, kArmJoints> axis, origin;
  (void)pass(axis, origin);
  return f_ * flange_tool_;
}

Eigen::Isometry3d ArmIk::pass(std::array<Eigen::Vector3d, kArmJoints>& axis,
                              std::array<Eigen::Vector3d, kArmJoints>& origin) noexcept {
  std::array<double, kArmJoints> q;
  for (int j = 0; j < kArmJoints; ++j) q[static_cast<std::size_t>(j)] = q_(j);
  Eigen::Isometry3d flange;
  rt_chain_->pass(q, axis, origin, flange);
  const Eigen::Matrix3d& r = flange.linear();
  const Eigen::Vector3d& p = flange.translation();
  f_ = KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0),
                                r(2, 1), r(2, 2)),
                  KDL::Vector(p.x(), p.y(), p.z()));
  return flange;
}

void ArmIk::pose_and_jacobian(Eigen::Matrix<double, 6, kArmJoints>& J) noexcept {
  // Each joint's axis and origin in the world before its own motion, then the flange; column
  // j = [a_j x (p_tool - o_j); a_j] (the geometric Jacobian at the tool frame's origin, what
  // KDL's ChainJntToJacSolver with changeRefPoint gives).
  std::array<Eigen::Vector3d, kArmJoints> axis, origin;
  const Eigen::Isometry3d flange = pass(axis, origin);
  const Eigen::Vector3d p_tool =
      flange * Eigen::Vector3d(flange_tool_.p.x(), flange_tool_.p.y(), flange_tool_.p.z());
  for (int k = 0; k < kArmJoints; ++k) {
    const auto& a = axis[static_cast<std::size_t>(k)];
    J.col(k).head<3>() = a.cross(p_tool - origin[static_cast<std::size_t>(k)]);
    J.col(k).tail<3>() = a;
  }
}

Eigen::Matrix<double, 6, kArmJoints> ArmIk::tool_jacobian(std::span<const double, kArmJoints> q) noexcept {
  for (int j = 0; j < kArmJoints; ++j) q_(j) = q[j];
  Eigen::Matrix<double, 6, kArmJoints> J;
  pose_and_jacobian(J);
  return J;
}

void ArmIk::random_seed(std::span<double, kArmJoints> q) noexcept {
  for (int j = 0; j < kArmJoints; ++j) {
    rng_ ^= rng_ << 13;  // xorshift64
    rng_ ^= rng_ >> 7;
    rng_ ^= rng_ << 17;
    const double u = static_cast<double>(rng_ >> 11) * (1.0 / 9007199254740992.0);
    // Within the middle 80 % of each range: seeds at a limit start locked.
    q[j] = lo_[j] + (0.1 + 0.8 * u) * (hi_[j] - lo_[j]);
  }
}

bool ArmIk::iterate(const KDL::Frame& target, int max_iterations, double rest_gain, double rest_max_step,
                    double tol_m, double tol_rad, Result& r) noexcept {
  bool null_pending = rest_gain > 0;
  bool locked[kArmJoints] = {};
  Mat67 J;
  for (int it = 0;; ++it) {
    pose_and_jacobian(J);
    const KDL::Frame tool = f_ * flange_tool_;
    // Position error, and the orientation error 1/2 sum_i (r_i x r_target_i) = sin(theta) axis
    // (exact at small angles: KDL::diff reads rotations under ~1e-6 rad as none).
    const KDL::Vector ev = target.p - tool.p;
    const KDL::Vector er = 0.5 * (tool.M.UnitX() * target.M.UnitX() + tool.M.UnitY() * target.M.UnitY() +
                                  tool.M.UnitZ() * target.M.UnitZ());
    r.error_m = std::sqrt(KDL::dot(ev, ev));
    r.error_rad = std::sqrt(KDL::dot(er, er));
    // Beyond 90 deg sin(theta) falls again: count the angle as at least 1 there.
    if (KDL::dot(tool.M.UnitX(), target.M.UnitX()) + KDL::dot(tool.M.UnitY(), target.M.UnitY()) +
            KDL::dot(tool.M.UnitZ(), target.M.UnitZ()) < 1.0) {
      r.error_rad = std::max(r.error_rad, 1.0);
    }
    const bool converged = r.error_m < tol_m && r.error_rad < tol_rad;
    if ((converged && !null_pending) || it >= max_iterations) return converged;

    Vec6 e;
    e << ev.x(), ev.y(), ev.z(), er.x(), er.y(), er.z();
    // A locked joint comes free when the error pulls it back inside its range.
    const Vec7 g = J.transpose() * e;
    for (int j = 0; j < kArmJoints; ++j) {
      if (locked[j] && ((q_(j) <= lo_[j] && g(j) > 0) || (q_(j) >= hi_[j] && g(j) < 0))) locked[j] = false;
      if (locked[j]) J.col(j).setZero();
    }
    const double e2 = e.squaredNorm();
    const double lambda2 = opt_.lambda0 * opt_.lambda0 + opt_.lambda_per_error * opt_.lambda_per_error * e2;
    const Mat6 A = J * J.transpose() + lambda2 * Mat6::Identity();
    const Eigen::LDLT<Mat6> ldlt(A);
    Vec7 dq = J.transpose() * ldlt.solve(e);
    if (null_pending) {
      Vec7 z;
      for (int j = 0; j < kArmJoints; ++j) {
        z(j) = locked[j] ? 0.0 : std::clamp(rest_gain * (opt_.rest_rad[j] - q_(j)), -rest_max_step, rest_max_step);
      }
      dq += z - J.transpose() * ldlt.solve(J * z);  // (I - J^+ J) z
      null_pending = false;
    }
    const double biggest = dq.cwiseAbs().maxCoeff();
    if (biggest > opt_.max_step_rad) dq *= opt_.max_step_rad / biggest;
    for (int j = 0; j < kArmJoints; ++j) {
      double v = q_(j) + dq(j);
      if (opt_.respect_limits) {
        if (v <= lo_[j]) {
          v = lo_[j];
          locked[j] = true;
        } else if (v >= hi_[j]) {
          v = hi_[j];
          locked[j] = true;
        }
      }
      q_(j) = v;
    }
    ++r.iterations;
  }
}

ArmIk::Result ArmIk::solve(const KDL::Frame& target, std::span<const double, kArmJoints> seed,
                           std::span<double, kArmJoints> q) noexcept {
  Result r, attempt;
  double best = INFINITY;
  Joints start{}, best_q{};
  for (int j = 0; j < kArmJoints; ++j) start[j] = opt_.respect_limits ? std::clamp(seed[j], lo_[j], hi_[j]) : seed[j];
  for (int a = 0; a <= opt_.restarts; ++a) {
    if (a > 0) random_seed(start);
    for (int j = 0; j < kArmJoints; ++j) q_(j) = start[j];
    attempt = Result{};
    const bool ok = iterate(target, opt_.max_iterations, a == 0 ? opt_.rest_gain : 0.0, opt_.max_step_rad, opt_.tolerance_m,
                            opt_.tolerance_rad, attempt);
    r.iterations += attempt.iterations;
    r.attempts = a + 1;
    // Best: converged first, then the smaller error (1 mm counts as 1 mrad).
    const double score = (ok ? 0.0 : 1e6) + attempt.error_m + attempt.error_rad;
    if (score < best) {
      best = score;
      r.converged = ok;
      r.error_m = attempt.error_m;
      r.error_rad = attempt.error_rad;
      for (int j = 0; j < kArmJoints; ++j) best_q[j] = q_(j);
    }
    if (ok) break;
  }
  for (int j = 0; j < kArmJoints; ++j) q[j] = best_q[j];
  return r;
}

ArmIk::Result ArmIk::track(const KDL::Frame& target, std::span<double, kArmJoints> q) noexcept {
  Result r;
  for (int j = 0; j < kArmJoints; ++j) q_(j) = q[j];
  r.attempts = 1;
  r.converged = iterate(target, opt_.track_iterations, opt_.track_rest_gain, opt_.track_rest_max_step_rad,
                        opt_.track_tolerance_m, opt_.track_tolerance_rad, r);
  for (int j = 0; j < kArmJoints; ++j) q[j] = q_(j);
  return r;
}

}  // namespace crease::robot
