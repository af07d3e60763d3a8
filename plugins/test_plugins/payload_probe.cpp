// Test plugin: reads bridged `hand_state` and `keypoints` ports (params hand_state, keypoints:
// which, default both) and pushes, for each new value, how old it was into the `latency` queue
// (crease::test_plugins::LatencySample), for `crease-bench dds`. Degraded until both inputs it
// reads have data.
#include "core/plugin.h"
#include "core/port_types/hand.h"
#include "core/port_types/keypoints.h"
#include "plugins/test_plugins/test_ports.h"
#include "rt/clock.h"

namespace {
using crease::test_plugins::LatencySample;

class PayloadProbe final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    hand_ = p.get<bool>("hand_state", true);
    kp_ = p.get<bool>("keypoints", true);
    if (hand_) state_ = ports.latest_input<crease::HandState>("hand_state");
    if (kp_) keypoints_ = ports.latest_input<crease::Keypoints>("keypoints");
    out_ = ports.queue_output<LatencySample>("latency", 1 << 16);
  }
  crease::Status update(const crease::Cycle&) override {
    bool all = true;
    if (hand_) {
      const crease::rt::ReadInfo info = state_.poll();
      all = all && info.has_data();
      if (info.is_new())
        (void)out_.try_push(LatencySample{state_.value().timestamp_ns, info.stamp_ns, crease::rt::now_ns(),
                                          state_.value().commands_sent, LatencySample::hand_state, 0});
    }
    if (kp_) {
      const crease::rt::ReadInfo info = keypoints_.poll();
      all = all && info.has_data();
      if (info.is_new())
        (void)out_.try_push(LatencySample{keypoints_.value().timestamp_ns, info.stamp_ns, crease::rt::now_ns(),
                                          keypoints_.value().frame, LatencySample::keypoints,
                                          keypoints_.value().count});
    }
    return all ? crease::Status::ok : crease::Status::degraded;
  }

 private:
  bool hand_ = true;
  bool kp_ = true;
  crease::LatestInput<crease::HandState> state_;
  crease::LatestInput<crease::Keypoints> keypoints_;
  crease::QueueOutput<LatencySample> out_;
};
}  // namespace

CREASE_PLUGIN(PayloadProbe, "test_payload_probe", "1.0.0")
