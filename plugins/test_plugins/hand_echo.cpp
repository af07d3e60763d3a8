// Test plugin: a hand controller stand-in that answers every hand_state with a hand_command
// carrying the device time of the status it was built from, so the device side can tell how
// many cycles old the sensing behind each command was (drivers/simdevice/sense_to_command_tap.h).
// Joints 0..2 encode device_time_us in 10-bit pieces (encode_device_time); the others hold 0.2.
#include "core/plugin.h"
#include "core/port_types/hand.h"
#include "drivers/simdevice/sense_to_command_tap.h"

namespace {
class HandEcho final : public crease::Plugin {
 public:
  void configure(const crease::Params&, crease::PortBinder& ports) override {
    state_ = ports.latest_input<crease::HandState>("hand_state");
    command_ = ports.latest_output<crease::HandCommand>("hand_command", crease::HandCommand{});
  }
  crease::Status update(const crease::Cycle& cycle) override {
    if (!state_.poll().has_data()) return crease::Status::degraded;
    crease::HandCommand c;
    c.timestamp_ns = cycle.time_ns;
    c.enable = 1;
    for (int j = 0; j < crease::HandCommand::kJoints; ++j) {
      c.target_rad[j] = 0.2f;
      c.stiffness_nm_per_rad[j] = 1.0f;
    }
    crease::drivers::sim::encode_device_time(state_.value().device_time_us, c.target_rad);
    command_.write(c, cycle.time_ns);
    return crease::Status::ok;
  }

 private:
  crease::LatestInput<crease::HandState> state_;
  crease::LatestOutput<crease::HandCommand> command_;
};
}  // namespace

CREASE_PLUGIN(HandEcho, "test_hand_echo", "1.0.0")
