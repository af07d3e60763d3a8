// Hand and arm states as ROS 2's sensor_msgs/msg/JointState (idl/JointState.idl): the view a
// publish entry with `view: joint_state` puts on its topic instead of the payload's own
// crease_msgs type, so that ROS 2 tools (robot_state_publisher, rviz, ros2 topic echo) read the
// joints without Crease's messages. Publish only: JointState has no health, validity, safe state
// or acknowledged command, which the controllers need.
//   name      joint_prefix + the URDF's joint names in the payload's joint order
//             (plugins/robot_model/robot_layout.h: S1..W2 for an arm, WRJ2..THJ1 for a hand)
//   position  rad; NaN for a joint the driver did not measure in that status (its valid bit)
//   velocity  rad/s for an arm (NaN likewise); empty for a hand (it reports none)
//   effort    empty
//   header    stamp: the payload's CLOCK_MONOTONIC time moved to CLOCK_REALTIME (ROS time) when
//             it is published; frame_id empty
#pragma once

#include <time.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "JointState.h"
#include "core/port_types/arm.h"
#include "core/port_types/hand.h"
#include "mirror.h"
#include "plugins/robot_model/robot_layout.h"

namespace crease::dds_bridge {

// The joints of a payload that has a JointState view.
template <class T>
struct Joints;
template <>
struct Joints<crease::HandState> {
  static constexpr int kCount = crease::HandState::kJoints;
  static constexpr const auto& kNames = crease::robot::kHandJointNames;
  static constexpr bool kVelocity = false;
};
template <>
struct Joints<crease::ArmState> {
  static constexpr int kCount = crease::ArmState::kJoints;
  static constexpr const auto& kNames = crease::robot::kArmJointNames;
  static constexpr bool kVelocity = true;
};
static_assert(Joints<crease::HandState>::kCount == crease::robot::kHandJoints);
static_assert(Joints<crease::ArmState>::kCount == crease::robot::kArmJoints);

template <class T>
struct JointStateView {
  using C = sensor_msgs_msg_dds__JointState_;
  static constexpr int kN = Joints<T>::kCount;
  // What the sample's strings and sequences point into (the publisher thread's own).
  struct Scratch {
    explicit Scratch(const std::string& prefix = {}) {
      for (int j = 0; j < kN; ++j) names[j] = prefix + std::string(Joints<T>::kNames[static_cast<std::size_t>(j)]);
      for (int j = 0; j < kN; ++j) name_ptrs[j] = names[j].data();
    }
    Scratch(const Scratch&) = delete;
    Scratch& operator=(const Scratch&) = delete;
    std::string names[kN];
    char* name_ptrs[kN];
    double position[kN];
    double velocity[kN];
    char frame_id[1] = {'\0'};
  };
  static const dds_topic_descriptor_t* descriptor() noexcept { return &sensor_msgs_msg_dds__JointState__desc; }

  // The monotonic stamp `t_ns` on the realtime clock, as ROS 2's builtin_interfaces/Time.
  static void stamp(std::int64_t t_ns, builtin_interfaces_msg_dds__Time_& out) noexcept {
    timespec mono{}, real{};
    clock_gettime(CLOCK_MONOTONIC, &mono);
    clock_gettime(CLOCK_REALTIME, &real);
    const std::int64_t offset = (static_cast<std::int64_t>(real.tv_sec) - mono.tv_sec) * 1'000'000'000 +
                                (static_cast<std::int64_t>(real.tv_nsec) - mono.tv_nsec);
    std::int64_t t = t_ns + offset;
    if (t < 0) t = 0;
    out.sec = static_cast<std::int32_t>(t / 1'000'000'000);
    out.nanosec = static_cast<std::uint32_t>(t % 1'000'000'000);
  }

  static void to_dds(const T& src, C& dst, Scratch& s) noexcept {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    stamp(src.timestamp_ns, dst.header.stamp);
    dst.header.frame_id = s.frame_id;
    for (int j = 0; j < kN; ++j) {
      const bool measured = ((static_cast<std::uint32_t>(src.valid) >> j) & 1u) != 0;
      s.position[j] = measured ? static_cast<double>(src.position_rad[j]) : kNaN;
      if constexpr (Joints<T>::kVelocity) s.velocity[j] = measured ? static_cast<double>(src.velocity_rad_s[j]) : kNaN;
    }
    set(dst.name, s.name_ptrs, kN);
    set(dst.position, s.position, kN);
    set(dst.velocity, s.velocity, Joints<T>::kVelocity ? kN : 0);
    set(dst.effort, static_cast<double*>(nullptr), 0);
  }

 private:
  template <class Seq, class E>
  static void set(Seq& seq, E* data, int n) noexcept {
    const auto len = static_cast<std::uint32_t>(n);
    lend_sequence(seq, n > 0 ? data : nullptr, len, len);
  }
};

}  // namespace crease::dds_bridge
