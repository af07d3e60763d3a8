// The names the robot's URDF must provide (config/robot/crease_robot.urdf), in the orders the
// drivers use on the wire (drivers/README.md §3 and §4). Every name is prefixed with its side's
// prefix from the robot's YAML (r_, l_).
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace crease::robot {

enum class Side : std::uint8_t { right = 0, left = 1 };
inline constexpr int kSides = 2;
inline constexpr std::array<std::string_view, kSides> kSideNames = {"right", "left"};

// The PA-10's seven joints, base to flange: the arm protocol's joint order (§4).
inline constexpr int kArmJoints = 7;
inline constexpr std::array<std::string_view, kArmJoints> kArmJointNames = {
    "S1", "S2", "S3", "E1", "E2", "W1", "W2"};

// The hand's 20 actuated joints: the hand protocol's joint order (§3). FFJ1, MFJ1, RFJ1 and
// LFJ1 are not among them: each is a URDF <mimic> of its finger's J2.
inline constexpr int kHandJoints = 20;
inline constexpr std::array<std::string_view, kHandJoints> kHandJointNames = {
    "WRJ2", "WRJ1",                  // wrist
    "FFJ4", "FFJ3", "FFJ2",          // first finger: abduction, MCP, PIP (+ DIP coupled)
    "MFJ4", "MFJ3", "MFJ2",          // middle finger
    "RFJ4", "RFJ3", "RFJ2",          // ring finger
    "LFJ5", "LFJ4", "LFJ3", "LFJ2",  // little finger: metacarpal, then as the others
    "THJ5", "THJ4", "THJ3", "THJ2", "THJ1"};  // thumb: base rotation ... distal flexion

// The index of a hand joint by its name without prefix ("FFJ3" -> 3), or -1.
[[nodiscard]] constexpr int hand_joint_index(std::string_view name) noexcept {
  for (int j = 0; j < kHandJoints; ++j)
    if (kHandJointNames[static_cast<std::size_t>(j)] == name) return j;
  return -1;
}

// The finger a hand joint moves (0 ff, 1 mf, 2 rf, 3 lf, 4 th; kFingertipNames' order), or -1
// for the wrist.
[[nodiscard]] constexpr int finger_of_hand_joint(int j) noexcept {
  if (j < 2) return -1;
  if (j < 5) return 0;
  if (j < 8) return 1;
  if (j < 11) return 2;
  if (j < 15) return 3;
  return 4;
}

// Flexion joints of the four fingers: J3 (MCP) and J2 (PIP, with the coupled DIP). The thumb's
// and the abduction joints are not.
[[nodiscard]] constexpr bool is_finger_flexion_joint(int j) noexcept {
  const int f = finger_of_hand_joint(j);
  if (f < 0 || f > 3) return false;
  const std::string_view n = kHandJointNames[static_cast<std::size_t>(j)];
  return n.ends_with("J3") || n.ends_with("J2");
}

// Fingertips in the order of the tactile and pressure frames (§3, §6).
inline constexpr int kFingertips = 5;
inline constexpr std::array<std::string_view, kFingertips> kFingertipNames = {"ff", "mf", "rf", "lf",
                                                                               "th"};

// Tool frames: links of each side whose world pose the kinematics serves. Pads and backs: the
// fingertip's palmar (tactile) and dorsal surfaces; palmfront: the palm's palmar surface. Their
// origin is on the surface, z the outward normal, x along the finger towards its tip (palm:
// towards the fingers). flange: the PA-10's tool flange (the end of the arm's own chain).
enum class ToolFrame : std::uint8_t {
  ff_pad, mf_pad, rf_pad, lf_pad, th_pad,
  ff_back, mf_back, rf_back, lf_back, th_back,
  palm_front, flange,
};
inline constexpr int kToolFrames = 12;
inline constexpr std::array<std::string_view, kToolFrames> kToolFrameLinks = {
    "ffpad",  "mfpad",  "rfpad",  "lfpad",  "thpad",     "ffback",
    "mfback", "rfback", "lfback", "thback", "palmfront", "flange"};

// The pad and back tool frames of fingertip f (0..4, kFingertipNames' order).
[[nodiscard]] constexpr ToolFrame pad_frame(int f) noexcept { return static_cast<ToolFrame>(f); }
[[nodiscard]] constexpr ToolFrame back_frame(int f) noexcept {
  return static_cast<ToolFrame>(kFingertips + f);
}

// The world frame's link: z up, origin on the table surface. Every chain starts here.
inline constexpr std::string_view kWorldLink = "world";

}  // namespace crease::robot
