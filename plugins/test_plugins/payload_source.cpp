// Test plugin: writes the payloads a bridge carries, stamped when written, for the dds_bridge
// tests and `crease-bench dds`. Every cycle `hand_state` (crease::HandState: device_time_us and
// commands_sent = the cycle index, position_rad[j] = 0.01 j + 1e-6 (index mod 1000)); every
// `keypoints_every` cycles (0 = never) `keypoints` (crease::Keypoints: frame = the cycle index,
// `keypoints_count` points, point i at world (i, 2i, 3i) mm, marker i / 5, corner i mod 5).
// timestamp_ns of both is rt::now_ns() at the write (what latency is measured from).
#include <algorithm>
#include <memory>

#include "core/plugin.h"
#include "core/port_types/hand.h"
#include "core/port_types/keypoints.h"
#include "rt/clock.h"

namespace {
class PayloadSource final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    hand_ = p.get<bool>("hand_state", true);
    every_ = p.get_in_range<int>("keypoints_every", 0, 0, 1'000'000);
    count_ = p.get_in_range<int>("keypoints_count", 512, 0, static_cast<int>(crease::Keypoints::kCapacity));
    if (hand_) state_out_ = ports.latest_output<crease::HandState>("hand_state", crease::HandState{});
    if (every_ > 0) kp_out_ = ports.latest_output<crease::Keypoints>("keypoints", crease::Keypoints{});
    kp_ = std::make_unique<crease::Keypoints>();
  }
  crease::Status update(const crease::Cycle& cycle) override {
    if (hand_) {
      crease::HandState s;
      s.device_time_us = static_cast<std::uint32_t>(cycle.index);
      s.valid = (1u << crease::HandState::kJoints) - 1;
      for (int j = 0; j < crease::HandState::kJoints; ++j)
        s.position_rad[j] = 0.01f * static_cast<float>(j) + 1e-6f * static_cast<float>(cycle.index % 1000);
      s.fresh = 1;
      s.health = crease::DeviceHealth::ok;
      s.safe_state = 0;
      s.commands_sent = cycle.index;
      s.timestamp_ns = crease::rt::now_ns();
      state_out_.write(s, cycle.time_ns);
    }
    if (every_ > 0 && cycle.index % static_cast<std::uint64_t>(every_) == 0) {
      kp_->frame = cycle.index;
      kp_->count = static_cast<std::uint32_t>(count_);
      kp_->cameras_ok = 0x1f;
      for (int i = 0; i < count_; ++i) {
        crease::Keypoint& k = kp_->points[i];
        const float f = static_cast<float>(i);
        k.world_mm[0] = f;
        k.world_mm[1] = 2 * f;
        k.world_mm[2] = 3 * f;
        k.sheet_mm[0] = f;
        k.sheet_mm[1] = -f;
        k.reproj_error_px = 0.5f;
        k.marker_id = static_cast<std::uint16_t>(i / 5);
        k.corner = static_cast<std::uint8_t>(i % 5);
        k.face = 0;
        k.views = 0x3;
      }
      kp_->timestamp_ns = crease::rt::now_ns();
      kp_out_.write(*kp_, cycle.time_ns);
    }
    return crease::Status::ok;
  }

 private:
  bool hand_ = true;
  int every_ = 0;
  int count_ = 512;
  crease::LatestOutput<crease::HandState> state_out_;
  crease::LatestOutput<crease::Keypoints> kp_out_;
  std::unique_ptr<crease::Keypoints> kp_;
};
}  // namespace

CREASE_PLUGIN(PayloadSource, "test_payload_source", "1.0.0")
