// Plugin `hand_driver`: one 20-joint hand over CAN FD (and, optionally, its tactile matrix
// over serial) in the 1 kHz control loop. Non-blocking CAN I/O in the loop; the serial tactile
// link is read and written by a thread of its own (drivers/host/tactile_reader.h: a tty's
// non-blocking read can stay in the kernel for milliseconds), update only takes its samples.
//   input  hand_command (latest HandCommand)
//   output hand_state   (latest HandState: positions, health, freshness, acks)
//   output tactile      (latest Tactile, when `tactile_device` is set: the newest sample, its
//                       age and health, the link's frames, CRC errors and overruns)
// Parameters:
//   bus_kind        "mock" (user-space bus, default) or "socketcan"
//   bus             mock bus name, or the SocketCAN interface (e.g. can0)        required
//   node            device node id 1..126                                         required
//   host_node       our node id on a mock bus (default 100)
//   pressure_sensors true for the left hand's air-pressure sensors (default false)
//   tactile_device  serial device of the tactile matrix (default: none); a bare name (no '/')
//                   with bus_prefix is the simulated robot's link of that name
//                   (drivers/host/bus_prefix.h: simulated_link_path; sim_world serves it on a Unix
//                   socket, drivers/serial/unix_link.h; sim_devices on a pty)
//   tactile_rate_hz 1..1000 (default 250)
//   tactile_priority 0..98: the reader thread's SCHED_FIFO priority where permitted (default 1,
//                   below every loop; 0: SCHED_OTHER)
//   timeout_cycles  cycles without a fresh status before fault (default 2)
//   crc_threshold   bad-CRC frames per 100 cycles before fault (default 10)
//   device_fault_cycles cycles in fault before it is reported as a device fault (default 50)
//   bus_off_grace_cycles a bus-off's cycles reported degraded, not fault (default 3)
// Threads: the tactile link's reader thread ("crease-tactile", on the non-RT CPUs, SCHED_FIFO
// tactile_priority where permitted) runs from
// activate to deactivate: it sends Start, deframes and decodes, and queues every sample.
// Cycle phases: update reads the bus, takes the queued tactile samples and publishes
// hand_state / tactile; write sends the newest
// hand_command, so a controller that runs after the driver in the loop has its command sent in
// the same cycle as the status it was built from.
// A link fault (device silent, bus-off, CRC errors, emergency) commands the safe state (hold,
// zero force) in the same cycle and is reported as Status::degraded, and as Status::device_fault
// once it lasted device_fault_cycles (the host counts a device fault; never before the device
// first answered) with health = fault in
// hand_state: the plugin stays scheduled so it recovers by itself when the device returns,
// sending the newest command, never a backlog. Before the first command arrives it holds.
// The tactile link likewise: stale samples (older than 20 ms: health fault in `tactile`) are
// Status::degraded, and Status::device_fault once they lasted device_fault_cycles after the
// sensor's first sample (or its 1000 first-contact cycles); the hand is not made safe for it
// (its controllers see the tactile port's health), and the report recovers with the samples.
#include <unistd.h>

#include <memory>
#include <string>
#include <utility>

#include "core/plugin.h"
#include "core/port_types/hand.h"
#include "core/port_types/tactile.h"
#include "drivers/host/bus_prefix.h"
#include "drivers/host/device_port_glue.h"
#include "drivers/host/hand_host.h"
#include "drivers/host/tactile_reader.h"
#include "drivers/serial/serial_io.h"
#include "drivers/serial/serial_port.h"
#include "drivers/serial/unix_link.h"

namespace {
using namespace crease;
namespace dr = crease::drivers;

class HandDriver final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    dr::HandHostConfig cfg;
    bus_ = dr::configure_can_device(p, cfg, 1);
    report_ = dr::DeviceFaultReport(cfg.monitor.device_fault_cycles);
    tactile_report_ = dr::DeviceFaultReport(cfg.monitor.device_fault_cycles);
    tactile_first_contact_cycles_ = static_cast<std::uint64_t>(cfg.monitor.first_contact_cycles);
    cfg.pressure_sensors = p.get<bool>("pressure_sensors", false);
    host_ = std::make_unique<dr::HandHost>(*bus_, cfg);
    if (p.has("tactile_device")) {
      std::string dev = p.get<std::string>("tactile_device");
      if (dev.find('/') == std::string::npos) {  // a bare name: a simulated robot's link
        const auto prefix = dr::bus_prefix_from_params(p, std::nullopt);
        if (!prefix) p.fail("tactile_device", "a bare name is a simulated robot's link and needs bus_prefix; a device is a path");
        if (!dr::valid_link_name(dev)) p.fail("tactile_device", "a link name is 1..32 of [A-Za-z0-9._-]");
        dev = dr::simulated_link_path(*prefix, dev);
      }
      int fd = -1;
      try {
        // A simulated robot's link is a Unix socket (sim_world) or a pty (sim_devices); a
        // sensor is a tty.
        if (dr::is_unix_socket(dev)) {
          socket_ = UniqueFd(dr::connect_unix_link(dev));
          fd = socket_.fd;
        } else {
          serial_ = std::make_unique<dr::SerialPort>(dr::SerialConfig{dev, 1'000'000, false});
          fd = serial_->fd();
        }
      } catch (const std::exception& e) {
        p.fail("tactile_device", e.what());
      }
      dr::TactileHostConfig tc;
      tc.rate_hz = static_cast<std::uint16_t>(p.get_in_range<int>("tactile_rate_hz", 250, 1, 1000));
      // Older than this, the taxels are a link fault (the default: 5 samples at 250 Hz).
      tc.max_age_ns = static_cast<std::int64_t>(
          1e6 * p.get_in_range<double>("tactile_max_age_ms", static_cast<double>(tc.max_age_ns) / 1e6, 1.0, 1000.0));
      tc.thread_priority = p.get_in_range<int>("tactile_priority", tc.thread_priority, 0, 98);
      tactile_ = std::make_unique<dr::TactileReader>(std::make_unique<dr::FdSerialIo>(fd), tc, "crease-tactile");
      tactile_out_ = ports.latest_output<Tactile>("tactile", Tactile{});
    }
    command_ = ports.latest_input<HandCommand>("hand_command");
    state_out_ = ports.latest_output<HandState>("hand_state", HandState{});
  }

  // Non-RT: the tactile link's thread runs while the instance is scheduled.
  void activate() override {
    tactile_cycles_ = 0;
    if (tactile_) tactile_->start();
  }
  void deactivate() override {
    if (tactile_) tactile_->stop();
  }

  // Read phase: the bus and the samples the tactile thread queued (no syscall on the serial
  // link here); publishes hand_state and tactile for the
  // controllers that run after this plugin's update in the same cycle.
  Status update(const Cycle& cycle) override {
    const std::int64_t now = cycle.time_ns;
    host_->read_from_rt(now);
    const dr::HandReading& r = host_->reading();
    dr::fill_link_state(state_, *host_);
    for (int j = 0; j < HandState::kJoints; ++j) state_.position_rad[j] = r.status.position_rad[j];
    for (int k = 0; k < HandState::kPressureSensors; ++k) state_.pressure_kpa[k] = r.pressure.pressure_kpa[k];
    state_.pressure_valid = r.pressure_fresh ? r.pressure.valid : 0;
    // The write phase of this cycle sends the safe state on a link fault; with no command, or a
    // disabled one (as held from the last write phase), it holds with zero force.
    const bool enabled = command_.has_value() && command_.value().enable;
    state_.safe_state = host_->health() == dr::LinkHealth::fault || !enabled ? 1 : 0;
    state_out_.write(state_, now);

    Status status = report_.update(host_->health(), host_->monitor());
    if (tactile_) {
      const bool got = tactile_->take_rt(now);
      const dr::tactile::Sample& s = tactile_->sample();
      tactile_out_value_.timestamp_ns = tactile_->sample_rx_ns();
      tactile_out_value_.device_time_us = s.device_time_us;
      tactile_out_value_.sample_counter = s.sample_counter;
      tactile_out_value_.valid = s.valid;
      tactile_out_value_.fresh = got ? 1 : 0;
      const dr::LinkHealth tactile_health = tactile_->health(now);
      tactile_out_value_.health = dr::to_device_health(tactile_health);
      tactile_out_value_.age_ns = tactile_->samples() ? now - tactile_out_value_.timestamp_ns : 0;
      const dr::TactileCounters c = tactile_->counters();
      tactile_out_value_.frames = tactile_->samples();
      tactile_out_value_.crc_errors = c.crc_errors;
      tactile_out_value_.overruns = c.overruns;
      for (int f = 0; f < Tactile::kFingertips; ++f)
        for (int t = 0; t < Tactile::kTaxels; ++t) tactile_out_value_.pressure_kpa[f][t] = s.pressure_kpa[f][t];
      tactile_out_.write(tactile_out_value_, now);
      // The sensor silent (or its samples stale) for device_fault_cycles after it first
      // answered, or after its first-contact cycles, is a device fault as the hand's would be.
      if (tactile_cycles_ < tactile_first_contact_cycles_) ++tactile_cycles_;
      const bool past_start_up = tactile_->samples() > 0 || tactile_cycles_ >= tactile_first_contact_cycles_;
      status = worst(status, tactile_report_.update(tactile_health, past_start_up));
    }
    status_ = status;
    return status;
  }

  // Write phase: the newest hand_command (written by a controller in this cycle's update, or
  // held from an earlier one) goes out with the SYNC; no command yet: hold the measured pose.
  Status write(const Cycle& cycle) {
    const dr::HandReading& r = host_->reading();
    dr::hand::Command cmd;
    dr::hand::Stiffness stiff;
    if (const HandCommand* in = dr::held_command(command_)) {
      cmd.flags = in->enable ? dr::hand::kCmdEnable : 0;
      for (int j = 0; j < HandCommand::kJoints; ++j) {
        cmd.target_rad[j] = in->target_rad[j];
        stiff.stiffness_nm_per_rad[j] = in->stiffness_nm_per_rad[j];
      }
    } else {
      for (int j = 0; j < HandCommand::kJoints; ++j) cmd.target_rad[j] = r.status.position_rad[j];
    }
    host_->write_from_rt(cmd, stiff, cycle.time_ns);
    return status_;
  }

 private:
  std::unique_ptr<dr::CanBus> bus_;
  dr::DeviceFaultReport report_;          // the hand's CAN link
  dr::DeviceFaultReport tactile_report_;  // the tactile link
  std::uint64_t tactile_cycles_ = 0;      // updates since activate, up to the first-contact cycles
  std::uint64_t tactile_first_contact_cycles_ = 1000;
  Status status_ = Status::degraded;      // this cycle's verdict of both links (update's, again in write)
  std::unique_ptr<dr::HandHost> host_;
  struct UniqueFd {
    int fd = -1;
    UniqueFd() = default;
    explicit UniqueFd(int f) : fd(f) {}
    UniqueFd(const UniqueFd&) = delete;
    UniqueFd& operator=(UniqueFd&& o) noexcept {
      std::swap(fd, o.fd);
      return *this;
    }
    ~UniqueFd() {
      if (fd >= 0) ::close(fd);
    }
  };
  std::unique_ptr<dr::SerialPort> serial_;
  UniqueFd socket_;                             // a simulated link's connection, or none
  std::unique_ptr<dr::TactileReader> tactile_;  // after serial_, socket_: stopped before they close
  LatestInput<HandCommand> command_;
  LatestOutput<HandState> state_out_;
  LatestOutput<Tactile> tactile_out_;
  HandState state_;
  Tactile tactile_out_value_;
};
}  // namespace

CREASE_PLUGIN(HandDriver, "hand_driver", "1.0.0")
