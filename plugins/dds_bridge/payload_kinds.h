// The port payloads a bridge can carry, each with its IDL type (idl/*.idl) and how to make a
// publish or subscribe link for a port of it. Non-RT.
//
// clang-format off
//   type          port payload          DDS type (ROS 2 name)
//   keypoints     crease::Keypoints     crease_msgs::msg::dds_::Keypoints_   (crease_msgs/msg/Keypoints)
//   hand_state    crease::HandState     crease_msgs::msg::dds_::HandState_   (crease_msgs/msg/HandState)
//   hand_command  crease::HandCommand   crease_msgs::msg::dds_::HandCommand_ (crease_msgs/msg/HandCommand)
//   arm_state     crease::ArmState      crease_msgs::msg::dds_::ArmState_    (crease_msgs/msg/ArmState)
//   arm_command   crease::ArmCommand    crease_msgs::msg::dds_::ArmCommand_  (crease_msgs/msg/ArmCommand)
//   sheet_state   crease::SheetState    crease_msgs::msg::dds_::SheetState_  (crease_msgs/msg/SheetState)
//   world_shapes  crease::WorldShapes   crease_msgs::msg::dds_::WorldShapes_ (crease_msgs/msg/WorldShapes)
// and two of queue ports (events, each delivered once, in order: queue_links.h):
//   sheet_crease   crease::SheetCreaseEvent   crease_msgs::msg::dds_::SheetCreaseEvent_
//   sheet_memorize crease::SheetMemorizeEvent crease_msgs::msg::dds_::SheetMemorizeEvent_
// hand_state and arm_state also publish as sensor_msgs/msg/JointState (`view: joint_state`,
// joint_state_view.h).
// clang-format on
#pragma once

#include <memory>
#include <span>
#include <string>

#include "core/port.h"
#include "links.h"

namespace crease::dds_bridge {

struct PayloadKind {
  const char* key;       // the entry's `type:`
  PortType port_type;    // of the local port
  bool queue;            // a queue port (events) rather than a latest port
  const char* dds_type;  // the topic's type name on the wire
  std::unique_ptr<PublishLink> (*make_publish)(PortBinder& ports, const std::string& port, dds_entity_t participant,
                                               const std::string& topic, const TopicQos& qos);
  std::unique_ptr<SubscribeLink> (*make_subscribe)(PortBinder& ports, const std::string& port,
                                                   dds_entity_t participant, const std::string& topic,
                                                   const TopicQos& qos);
  // The port published as sensor_msgs/msg/JointState, its joints named joint_prefix + the URDF's
  // names; nullptr for a payload without joints.
  std::unique_ptr<PublishLink> (*make_joint_state)(PortBinder& ports, const std::string& port,
                                                   dds_entity_t participant, const std::string& topic,
                                                   const TopicQos& qos, const std::string& joint_prefix);
};

[[nodiscard]] std::span<const PayloadKind> payload_kinds();
// By `type:` key, or by the port's payload type name and version; nullptr when none.
[[nodiscard]] const PayloadKind* find_payload_kind(const std::string& key);
[[nodiscard]] const PayloadKind* find_payload_kind(const std::string& port_type, std::uint32_t version);
// "keypoints, hand_state, ..." for messages.
[[nodiscard]] std::string payload_kind_keys();
// "hand_state, arm_state": the kinds with a JointState view.
[[nodiscard]] std::string joint_state_kind_keys();

}  // namespace crease::dds_bridge
