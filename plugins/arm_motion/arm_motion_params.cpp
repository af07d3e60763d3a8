#include "plugins/arm_motion/arm_motion_params.h"

#include <cmath>
#include <numbers>

namespace crease::arm_motion {

namespace {

std::array<double, 3> vec3(const Params& p, const char* key, std::array<double, 3> fallback) {
  if (!p.has(key)) return fallback;
  const YAML::Node n = p.raw(key);
  if (!n.IsSequence() || n.size() != 3) p.fail(key, "expected a list of 3 numbers (x, y, z mm)");
  std::array<double, 3> v{};
  for (std::size_t i = 0; i < 3; ++i) {
    try {
      v[i] = n[i].as<double>();
    } catch (const YAML::Exception&) {
      p.fail(key, "expected a list of 3 numbers, item " + std::to_string(i) + " is not a number");
    }
    if (!std::isfinite(v[i])) p.fail(key, "item " + std::to_string(i) + " is not finite");
  }
  return v;
}

}  // namespace

ArmMotionConfig parse_arm_motion_params(const Params& p) {
  ArmMotionConfig c;
  const std::string side = p.get<std::string>("side");
  if (side == "right") {
    c.side = robot::Side::right;
  } else if (side == "left") {
    c.side = robot::Side::left;
  } else {
    p.fail("side", "expected right or left, got '" + side + "'");
  }
  c.robot_path = p.get_path("robot", "robot/crease_robot.yaml");
  MotionParams& m = c.motion;
  GoalLimits& l = m.limits;
  l.max_speed_mm_s = p.get_in_range<double>("max_speed_mm_s", l.max_speed_mm_s, 1.0, 2000.0);
  l.max_accel_mm_s2 = p.get_in_range<double>("max_accel_mm_s2", l.max_accel_mm_s2, 1.0, 50000.0);
  l.max_angular_speed_rad_s = p.get_in_range<double>("max_angular_speed_rad_s", l.max_angular_speed_rad_s, 0.01, 6.0);
  l.max_angular_accel_rad_s2 = p.get_in_range<double>("max_angular_accel_rad_s2", l.max_angular_accel_rad_s2, 0.01, 500.0);
  l.max_stop_accel_mm_s2 = p.get_in_range<double>("max_stop_accel_mm_s2", l.max_stop_accel_mm_s2, 1.0, 100000.0);
  if (l.max_stop_accel_mm_s2 < l.max_accel_mm_s2) {
    p.fail("max_stop_accel_mm_s2", "must be at least max_accel_mm_s2 (" + format_number(l.max_accel_mm_s2) + ")");
  }
  m.workspace.min_mm = vec3(p, "workspace_min_mm", m.workspace.min_mm);
  m.workspace.max_mm = vec3(p, "workspace_max_mm", m.workspace.max_mm);
  for (int i = 0; i < 3; ++i) {
    if (!(m.workspace.min_mm[i] < m.workspace.max_mm[i])) {
      p.fail("workspace_max_mm", "must exceed workspace_min_mm in every axis (axis " + std::to_string(i) + ")");
    }
  }
  m.jerk_mm_s3 = p.get_in_range<double>("jerk_mm_s3", m.jerk_mm_s3, 0.0, 1e7);
  if (m.jerk_mm_s3 > 0) {
    m.angular_jerk_rad_s3 = p.get_in_range<double>("angular_jerk_rad_s3", m.angular_jerk_rad_s3, 0.01, 1e5);
    m.stop_jerk_mm_s3 = p.get_in_range<double>("stop_jerk_mm_s3", m.stop_jerk_mm_s3, 1.0, 1e8);
    if (m.stop_jerk_mm_s3 < m.jerk_mm_s3)
      p.fail("stop_jerk_mm_s3", "must be at least jerk_mm_s3 (" + format_number(m.jerk_mm_s3) + ")");
  } else {  // acceleration-limited: no jerk anywhere
    m.angular_jerk_rad_s3 = m.stop_jerk_mm_s3 = 0;
  }
  m.arm_state_max_age_s = 1e-3 * p.get_in_range<double>("arm_state_max_age_ms", 5.0, 0.5, 1000.0);
  m.hand_state_max_age_s = 1e-3 * p.get_in_range<double>("hand_state_max_age_ms", 20.0, 0.5, 1000.0);
  m.contact_state_max_age_s = 1e-3 * p.get_in_range<double>("contact_state_max_age_ms", 5.0, 0.5, 1000.0);
  m.sheet_state_max_age_s = 1e-3 * p.get_in_range<double>("sheet_state_max_age_ms", 200.0, 1.0, 10000.0);
  m.check_samples_per_cycle = p.get_in_range<int>("check_samples_per_cycle", m.check_samples_per_cycle, 1, 64);
  m.check_step_mm = p.get_in_range<double>("check_step_mm", m.check_step_mm, 0.1, 100.0);
  m.check_step_rad = p.get_in_range<double>("check_step_rad", m.check_step_rad, 0.001, 1.0);
  m.joint_speed_fraction = p.get_in_range<double>("joint_speed_fraction", m.joint_speed_fraction, 0.01, 1.0);
  m.joint_accel_rad_s2 = p.get_in_range<double>("joint_accel_rad_s2", m.joint_accel_rad_s2, 0.01, 20.0);
  m.ik.track_iterations = p.get_in_range<int>("track_iterations", m.ik.track_iterations, 1, 50);
  // The palm flat 150 mm above the table, 150 mm to the side's side of the centre and 50 mm
  // nearer the robot, fingers forward (+y): where the hands work; found with ArmIk for the arms
  // of config/robot (1 m over the table), every joint at least 28 deg inside its limits.
  m.ik.rest_rad = c.side == robot::Side::right
                      ? robot::ArmIk::Joints{-0.535, -0.993, -0.427, 1.890, 0.819, 1.125, 2.230}
                      : robot::ArmIk::Joints{0.535, -0.993, 0.426, 1.890, -0.819, 1.124, -2.230};
  if (p.has("rest_posture_deg")) {
    const YAML::Node n = p.raw("rest_posture_deg");
    if (!n.IsSequence() || n.size() != robot::kArmJoints) {
      p.fail("rest_posture_deg", "expected a list of 7 angles (deg, S1 S2 S3 E1 E2 W1 W2)");
    }
    for (int j = 0; j < robot::kArmJoints; ++j) {
      double d = 0;
      try {
        d = n[static_cast<std::size_t>(j)].as<double>();
      } catch (const YAML::Exception&) {
        p.fail("rest_posture_deg", "item " + std::to_string(j) + " is not a number");
      }
      if (!std::isfinite(d)) p.fail("rest_posture_deg", "item " + std::to_string(j) + " is not finite");
      m.ik.rest_rad[j] = d * std::numbers::pi / 180.0;
    }
  }
  return c;
}

void check_rest_posture(const Params& p, const ArmMotionConfig& c, const robot::RobotModel& m) {
  const auto& joints = m.arm_joints(c.side);
  for (int j = 0; j < robot::kArmJoints; ++j) {
    const double q = c.motion.ik.rest_rad[j];
    if (!(q >= joints[j].lower_rad && q <= joints[j].upper_rad)) {
      p.fail("rest_posture_deg", "joint " + joints[j].name + " at " + format_number(q * 180.0 / std::numbers::pi) +
                                     " deg is outside its limits [" +
                                     format_number(joints[j].lower_rad * 180.0 / std::numbers::pi) + ", " +
                                     format_number(joints[j].upper_rad * 180.0 / std::numbers::pi) + "] deg");
    }
  }
}

}  // namespace crease::arm_motion
