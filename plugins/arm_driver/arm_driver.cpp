// Plugin `arm_driver`: one 7-joint arm (CiA 402-like drive over CAN FD) in the 1 kHz loop.
//   input  arm_command (latest ArmCommand)
//   output arm_state   (latest ArmState: positions, velocities, drive state, health, acks)
// Parameters: bus_kind ("mock" | "socketcan"), bus (required), node (required, 1..126),
//   host_node (mock, default 100), timeout_cycles (2), crc_threshold (10).
// The drive is brought to operation enabled by the driver itself (and fault-reset when it
// reports a fault); set points reach it only there. A link fault commands quick stop in the
// same cycle and is reported as Status::degraded with health = fault: the plugin stays
// scheduled and recovers by itself, resending the newest set point. No command yet: hold.
#include <memory>
#include <string>

#include "core/plugin.h"
#include "core/port_types/arm.h"
#include "drivers/host/link_params.h"
#include "drivers/host/arm_host.h"

namespace {
using namespace crease;
namespace dr = crease::drivers;

class ArmDriver final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    dr::ArmHostConfig cfg;
    cfg.node = static_cast<std::uint8_t>(p.get_in_range<int>("node", 10, 1, 126));
    cfg.monitor = dr::monitor_from_params(p);
    bus_ = dr::open_bus_from_params(p);
    host_ = std::make_unique<dr::ArmHost>(*bus_, cfg);
    command_in_ = ports.latest_input<ArmCommand>("arm_command");
    state_out_ = ports.latest_output<ArmState>("arm_state", ArmState{});
  }

  Status update(const Cycle& cycle) override {
    const std::int64_t now = cycle.time_ns;
    host_->read_from_rt(now);
    const dr::ArmReading& r = host_->reading();
    const dr::LinkCounters& c = host_->monitor().counters();
    state_.timestamp_ns = r.status_rx_ns;
    state_.device_time_us = r.status.device_time_us;
    state_.valid = r.fresh ? r.status.valid : 0;
    state_.drive_state = static_cast<std::uint8_t>(r.drive);
    state_.error_code = r.status.error_code;
    for (int j = 0; j < ArmState::kJoints; ++j) {
      state_.position_rad[j] = r.status.position_rad[j];
      state_.velocity_rad_s[j] = r.status.velocity_rad_s[j];
    }
    state_.fresh = r.fresh ? 1 : 0;
    const dr::LinkHealth h = host_->health();
    state_.health = h == dr::LinkHealth::ok ? DeviceHealth::ok
                    : h == dr::LinkHealth::degraded ? DeviceHealth::degraded
                                                    : DeviceHealth::fault;
    state_.acked_seq = host_->monitor().last_acked_seq();
    state_.commands_sent = c.commands_sent;
    state_.commands_failed = c.commands_failed;

    ArmCommand in;
    if (command_in_.read(in).has_data()) {
      command_ = in;
      have_command_ = true;
    }
    dr::arm::Command cmd;
    if (have_command_) {
      cmd.mode = command_.mode == ArmCommand::velocity ? dr::arm::kModeCyclicVelocity : dr::arm::kModeCyclicPosition;
      for (int j = 0; j < ArmCommand::kJoints; ++j) {
        cmd.position_rad[j] = command_.position_rad[j];
        cmd.velocity_rad_s[j] = command_.velocity_rad_s[j];
      }
    } else {
      for (int j = 0; j < ArmCommand::kJoints; ++j) cmd.position_rad[j] = r.status.position_rad[j];
    }
    host_->write_from_rt(cmd, now);
    state_.safe_state = host_->commanding_safe_state() ? 1 : 0;
    state_out_.write(state_, now);
    return h == dr::LinkHealth::ok ? Status::ok : Status::degraded;
  }

 private:
  std::unique_ptr<dr::CanBus> bus_;
  std::unique_ptr<dr::ArmHost> host_;
  LatestInput<ArmCommand> command_in_;
  LatestOutput<ArmState> state_out_;
  ArmCommand command_;
  bool have_command_ = false;
  ArmState state_;
};
}  // namespace

CREASE_PLUGIN(ArmDriver, "arm_driver", "1.0.0")
