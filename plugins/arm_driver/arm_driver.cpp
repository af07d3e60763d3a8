// Plugin `arm_driver`: one 7-joint arm (CiA 402-like drive over CAN FD) in the 1 kHz loop.
//   input  arm_command (latest ArmCommand)
//   output arm_state   (latest ArmState: positions, velocities, drive state, health, acks)
// Parameters: bus_kind ("mock" | "socketcan"), bus (required), node (required, 1..126),
//   host_node (mock, default 100), timeout_cycles (2), crc_threshold (10),
//   device_fault_cycles (50), bus_off_grace_cycles (3).
// Cycle phases: update reads the bus and publishes arm_state; write sends the newest arm_command
// (a controller after the driver in the loop is answered in the same cycle).
// The drive is brought to operation enabled by the driver itself (and fault-reset when it
// reports a fault); set points reach it only there. A link fault commands quick stop in the
// same cycle and is reported as Status::degraded, and as Status::device_fault once it lasted
// device_fault_cycles (the host counts a device fault; never before the drive first answered),
// with health = fault: the plugin stays
// scheduled and recovers by itself, resending the newest set point. No command yet: hold.
#include <memory>
#include <string>

#include "core/plugin.h"
#include "core/port_types/arm.h"
#include "drivers/host/arm_host.h"
#include "drivers/host/device_port_glue.h"

namespace {
using namespace crease;
namespace dr = crease::drivers;

class ArmDriver final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    dr::ArmHostConfig cfg;
    bus_ = dr::configure_can_device(p, cfg, 10);
    report_ = dr::DeviceFaultReport(cfg.monitor.device_fault_cycles);
    host_ = std::make_unique<dr::ArmHost>(*bus_, cfg);
    command_ = ports.latest_input<ArmCommand>("arm_command");
    state_out_ = ports.latest_output<ArmState>("arm_state", ArmState{});
  }

  // Read phase: the bus; publishes arm_state for the controllers that run after it.
  Status update(const Cycle& cycle) override {
    const std::int64_t now = cycle.time_ns;
    host_->read_from_rt(now);
    const dr::ArmReading& r = host_->reading();
    dr::fill_link_state(state_, *host_);
    state_.drive_state = static_cast<std::uint8_t>(r.drive);
    state_.error_code = r.status.error_code;
    for (int j = 0; j < ArmState::kJoints; ++j) {
      state_.position_rad[j] = r.status.position_rad[j];
      state_.velocity_rad_s[j] = r.status.velocity_rad_s[j];
    }
    state_.safe_state = host_->health() == dr::LinkHealth::fault ? 1 : 0;  // this cycle's write sends quick stop
    state_out_.write(state_, now);
    return report_.update(host_->health(), host_->monitor());
  }

  // Write phase: the newest arm_command (this cycle's, or held) goes out with the SYNC.
  Status write(const Cycle& cycle) {
    const dr::ArmReading& r = host_->reading();
    dr::arm::Command cmd;
    if (const ArmCommand* in = dr::held_command(command_)) {
      cmd.mode = in->mode == ArmCommand::velocity ? dr::arm::kModeCyclicVelocity : dr::arm::kModeCyclicPosition;
      for (int j = 0; j < ArmCommand::kJoints; ++j) {
        cmd.position_rad[j] = in->position_rad[j];
        cmd.velocity_rad_s[j] = in->velocity_rad_s[j];
      }
    } else {
      for (int j = 0; j < ArmCommand::kJoints; ++j) cmd.position_rad[j] = r.status.position_rad[j];
    }
    host_->write_from_rt(cmd, cycle.time_ns);
    return report_.status();
  }

 private:
  std::unique_ptr<dr::CanBus> bus_;
  dr::DeviceFaultReport report_;
  std::unique_ptr<dr::ArmHost> host_;
  LatestInput<ArmCommand> command_;
  LatestOutput<ArmState> state_out_;
  ArmState state_;
};
}  // namespace

CREASE_PLUGIN(ArmDriver, "arm_driver", "1.0.0")
