#include "payload_kinds.h"

#include <cstring>

#include "arm_mirror.h"
#include "hand_mirror.h"
#include "joint_state_view.h"
#include "keypoints_mirror.h"
#include "queue_links.h"
#include "sheet_edit_mirror.h"
#include "sheet_mirror.h"
#include "world_shapes_mirror.h"

namespace crease::dds_bridge {

namespace {

template <class T>
PayloadKind kind_of() {
  using D = Dds<T>;
  if constexpr (requires { D::kQueue; }) {
    return PayloadKind{
        D::kKey, port_type_of<T>(), true, D::descriptor()->m_typename,
        [](PortBinder& ports, const std::string& port, dds_entity_t pp, const std::string& topic,
           const TopicQos& qos) -> std::unique_ptr<PublishLink> {
          return std::make_unique<QueuePublishLinkT<T, D>>(ports, port, pp, topic, qos);
        },
        [](PortBinder& ports, const std::string& port, dds_entity_t pp, const std::string& topic,
           const TopicQos& qos) -> std::unique_ptr<SubscribeLink> {
          return std::make_unique<QueueSubscribeLinkT<T, D>>(ports, port, pp, topic, qos);
        },
        nullptr};
  }
  PayloadKind k{
      D::kKey, port_type_of<T>(), false, D::descriptor()->m_typename,
      [](PortBinder& ports, const std::string& port, dds_entity_t pp, const std::string& topic,
         const TopicQos& qos) -> std::unique_ptr<PublishLink> {
        return std::make_unique<PublishLinkT<T, D>>(ports, port, pp, topic, qos);
      },
      [](PortBinder& ports, const std::string& port, dds_entity_t pp, const std::string& topic,
         const TopicQos& qos) -> std::unique_ptr<SubscribeLink> {
        return std::make_unique<SubscribeLinkT<T, D>>(ports, port, pp, topic, qos);
      },
      nullptr};
  if constexpr (requires { Joints<T>::kCount; }) {
    k.make_joint_state = [](PortBinder& ports, const std::string& port, dds_entity_t pp, const std::string& topic,
                            const TopicQos& qos, const std::string& prefix) -> std::unique_ptr<PublishLink> {
      using V = JointStateView<T>;
      return std::make_unique<PublishLinkT<T, V>>(ports, port, pp, topic, qos,
                                                  std::make_unique<typename V::Scratch>(prefix));
    };
  }
  return k;
}

const PayloadKind kKinds[] = {
    kind_of<crease::Keypoints>(),        kind_of<crease::HandState>(),
    kind_of<crease::HandCommand>(),      kind_of<crease::ArmState>(),
    kind_of<crease::ArmCommand>(),       kind_of<crease::SheetState>(),
    kind_of<crease::SheetCreaseEvent>(), kind_of<crease::SheetMemorizeEvent>(),
    kind_of<crease::WorldShapes>()};

}  // namespace

std::span<const PayloadKind> payload_kinds() { return kKinds; }

const PayloadKind* find_payload_kind(const std::string& key) {
  for (const PayloadKind& k : kKinds)
    if (key == k.key) return &k;
  return nullptr;
}

const PayloadKind* find_payload_kind(const std::string& port_type, std::uint32_t version) {
  for (const PayloadKind& k : kKinds)
    if (port_type == k.port_type.name && version == k.port_type.version) return &k;
  return nullptr;
}

std::string payload_kind_keys() {
  std::string s;
  for (const PayloadKind& k : kKinds) s += (s.empty() ? "" : ", ") + std::string(k.key);
  return s;
}

std::string joint_state_kind_keys() {
  std::string s;
  for (const PayloadKind& k : kKinds)
    if (k.make_joint_state != nullptr) s += (s.empty() ? "" : ", ") + std::string(k.key);
  return s;
}

}  // namespace crease::dds_bridge
