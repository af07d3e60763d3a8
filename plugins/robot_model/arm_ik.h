// Inverse kinematics of one 7-DOF arm to a tool frame's pose, the hand's angles held fixed.
//
//   ArmIk ik(model, Side::right, ArmIk::Options{});          // configure time: allocates
//   ik.set_tool(ToolFrame::ff_pad, arm_q, hand_q);            // RT: flange -> tool, this hand
//   posture ArmIk::Result r = ik.solve(target_world_m, seed_q, q);    // RT: from a seed, with
//   restarts r = ik.track(next_target_m, q);                            // RT: warm-started, a few
//   iterations
//
// The tool's pose is the flange's times a fixed flange -> tool offset, taken from the hand's
// angles by set_tool (so the arm alone positions the tool frame; a finger that moves later
// does not move the arm). The solver works on the world -> flange chain (the arm's 7 joints):
//
//   dq = J^T (J J^T + lambda^2 I)^-1 e  +  N k (q_rest - q),   N = I - J^+ J
//
// e the tool frame's pose error (position m; rotation 1/2 sum r_i x r_target_i = sin(theta) axis,
// exact at small angles), J the 6x7 geometric Jacobian at the tool frame's origin (one pass down
// the chain (arm_chain_rt.h), the pose with it; equal to KDL's ChainJntToJacSolver), lambda^2 =
// lambda0^2 + c |e|^2 (damped least squares, Levenberg-Marquardt style: robust far from the target,
// quadratic near it, bounded at singularities); the second term is the stated redundancy
// resolution: in the Jacobian's null space, towards a rest posture (by default elbow bent, wrist
// bent: the posture the arms work over the table in), applied once per call (k = rest_gain in
// solve, track_rest_gain in track) so it moves the elbow slowly and never the tool. Joint limits:
// each step is clamped to [lower, upper] (the URDF's), and a joint that reached a limit is locked
// (its Jacobian column zeroed) for the rest of the call, so the others complete the task; every
// returned q lies within the limits. solve() restarts from deterministic pseudo-random seeds within
// the limits when an attempt stalls.
//
// All buffers are fixed-size (Eigen fixed matrices, KDL arrays sized at construction): solve,
// track and set_tool allocate nothing, lock nothing, never throw. Not for concurrent calls.
// Metres and radians (KDL's units).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <memory>
#include <span>
#include <vector>

#include "plugins/robot_model/arm_chain_rt.h"
#include "plugins/robot_model/robot_model.h"

namespace crease::robot {

class ArmIk {
 public:
  using Joints = std::array<double, kArmJoints>;

  struct Options {
    int max_iterations = 60;        // per attempt of solve()
    int restarts = 8;               // further attempts of solve() from pseudo-random seeds
    int track_iterations = 4;       // per track() call
    double tolerance_m = 1e-6;      // converged: position error below this (1 um) ...
    double tolerance_rad = 1e-6;    // ... and rotation error below this (1 urad)
    double track_tolerance_m = 1e-9;    // track()'s: a command smooth to the nanometre (its
    double track_tolerance_rad = 1e-9;  //   second differences are accelerations)
    double lambda0 = 1e-3;          // damping floor (m-equivalent): bounds steps at singularities
    double lambda_per_error = 0.5;  // lambda^2 += (this * |e|)^2
    double max_step_rad = 0.3;      // per iteration, per joint
    double rest_gain = 0.02;        // fraction of (q_rest - q) per solve() attempt, in the null space
    double track_rest_gain = 5e-4;  // the same per track() call: at 1 kHz, 0.5 rad/s per rad away
    double track_rest_max_step_rad = 1e-4;  // and at most this per joint per call (0.1 rad/s at 1 kHz)
    Joints rest_rad = {0.0, 0.5, 0.0, 1.4, 0.0, 1.2, 0.0};  // elbow and wrist bent
    bool respect_limits = true;     // false only to show in tests what the limits change
  };

  struct Result {
    bool converged = false;   // within both tolerances (and the limits)
    int iterations = 0;       // over every attempt
    int attempts = 0;
    double error_m = 0;       // the tool frame's residual position error
    double error_rad = 0;     // and rotation error
  };

  // Non-RT: builds the arm's world -> flange chain, its FK and Jacobian solvers, and one chain per
  // tool frame for set_tool. Throws crease::ConfigError when the rest posture leaves the limits.
  ArmIk(const RobotModel& model, Side side, const Options& options);
  ArmIk(const RobotModel& model, Side side) : ArmIk(model, side, Options{}) {}
  ArmIk(ArmIk&&) = default;
  ArmIk& operator=(ArmIk&&) = default;

  // RT. Sets the tool frame and its flange -> tool offset from these arm and hand angles (the
  // offset depends on the hand only). False if KDL reported an error.
  bool set_tool(ToolFrame tool, std::span<const double, kArmJoints> arm, HandAngles hand) noexcept;
  // RT. Sets the offset directly (a motion carried across a hot-swap).
  void set_tool_offset(ToolFrame tool, const KDL::Frame& flange_tool) noexcept {
    tool_ = tool;
    flange_tool_ = flange_tool;
    tool_flange_ = flange_tool.Inverse();
  }
  [[nodiscard]] ToolFrame tool() const noexcept { return tool_; }
  [[nodiscard]] const KDL::Frame& tool_offset() const noexcept { return flange_tool_; }

  // RT. The tool frame's world pose at arm angles Q (with the offset set last).
  [[nodiscard]] KDL::Frame tool_pose(std::span<const double, kArmJoints> q) noexcept;
  // RT. The geometric Jacobian (linear rows first) at the tool frame's origin, world frame.
  [[nodiscard]] Eigen::Matrix<double, 6, kArmJoints> tool_jacobian(std::span<const double, kArmJoints> q) noexcept;

  // RT. Arm angles Q putting the tool frame at TARGET (world, metres), starting from SEED,
  // restarting when an attempt does not converge. Q is the best attempt's even when it failed.
  Result solve(const KDL::Frame& target, std::span<const double, kArmJoints> seed,
               std::span<double, kArmJoints> q) noexcept;
  // RT. At most track_iterations from Q itself (a warm start: the last cycle's solution), one
  // null-space step towards the rest posture first; Q in and out.
  Result track(const KDL::Frame& target, std::span<double, kArmJoints> q) noexcept;

  [[nodiscard]] const Joints& lower() const noexcept { return lo_; }
  [[nodiscard]] const Joints& upper() const noexcept { return hi_; }
  [[nodiscard]] const Joints& velocity_limit() const noexcept { return vmax_; }
  [[nodiscard]] const Options& options() const noexcept { return opt_; }
  [[nodiscard]] const KDL::Chain& arm_chain() const noexcept { return flange_chain_->chain(); }

 private:
  // Iterations from q_ (in place); returns whether converged. ITERATIONS counted in R.
  bool iterate(const KDL::Frame& target, int max_iterations, double rest_gain, double rest_max_step, double tol_m,
               double tol_rad, Result& r) noexcept;
  void pose_and_jacobian(Eigen::Matrix<double, 6, kArmJoints>& J) noexcept;  // at q_; sets f_
  // One pass down the chain at q_ (arm_chain_rt.h): sets f_, returns the flange pose.
  Eigen::Isometry3d pass(std::array<Eigen::Vector3d, kArmJoints>& axis,
                         std::array<Eigen::Vector3d, kArmJoints>& origin) noexcept;
  void random_seed(std::span<double, kArmJoints> q) noexcept;

  Options opt_;
  std::unique_ptr<ArmChainRt>
      rt_chain_;  // the chain's one forward kinematics (tool_pose, the iterations)
  std::vector<ToolChain> tools_;       // world -> each tool frame, for set_tool
  std::unique_ptr<ToolChain> flange_chain_;
  KDL::JntArray q_;
  KDL::Frame f_;
  KDL::Frame flange_tool_ = KDL::Frame::Identity();
  KDL::Frame tool_flange_ = KDL::Frame::Identity();
  ToolFrame tool_ = ToolFrame::flange;
  Joints lo_{}, hi_{}, vmax_{};
  std::uint64_t rng_ = 0x9e3779b97f4a7c15ull;
};

}  // namespace crease::robot
