// Plugin `sim_world`: the simulated world (sim_world.h: the robot of config/robot/, compliant
// hands, a physical sheet on the table) and the simulated robot's hardware it moves (the mocked
// CAN FD buses and the two hands and two arms of drivers/simdevice), stepped in lockstep from
// this plugin's update, one 1 ms world step per cycle (world_devices.h). Put it in a 1 kHz
// loop of its own, phased half a period after the control loop (`phase_us: 500`) so that the
// SYNC the drivers send in their write phase is answered before their next update; never in
// the control loop (a step costs about a fifth of a period).
//   output world_state  (latest WorldState: fingertips, contact forces, joint angles, counters)
//   output sheet_truth  (latest SheetState: the world's sheet, every truth_every_steps steps)
//   output world_shapes (latest WorldShapes: the arms' and hands' shapes, every shapes_every_steps
//                        steps, for the simulated cameras to draw)
// The fingertips' forces reach the drivers as tactile readings (world_tactile.h): the right
// hand's taxel matrix on a socket link (hand_driver `tactile_device: tactile_r`), the left hand's
// PST sensors in its pressure frames.
// The devices answer on `<bus_prefix>-hand_r`, `-hand_l`, `-arm_r`, `-arm_l` as sim_devices'
// do (this plugin takes its place; the drivers' parameters are the same). Parameters:
// world_config.h and README.md.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "core/plugin.h"
#include "core/port_types/sheet_state.h"
#include "core/port_types/world_shapes.h"
#include "core/port_types/world_state.h"
#include "drivers/host/bus_prefix.h"
#include "plugins/robot_model/robot_model.h"
#include "plugins/sim_world/bus_faults.h"
#include "plugins/sim_world/randomise.h"
#include "plugins/sim_world/sim_world.h"
#include "plugins/sim_world/world_config.h"
#include "plugins/sim_world/world_devices.h"
#include "plugins/sim_world/world_tactile.h"

namespace {

using namespace crease;
namespace wd = crease::world;

class SimWorldPlugin final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    cfg_ = wd::read_world_config(p);
    try {
      robot_ = std::make_unique<robot::RobotModel>(robot::RobotModel::load(cfg_.robot_yaml));
    } catch (const std::exception& e) {
      p.fail("robot", e.what());
    }
    try {
      world_ = std::make_unique<wd::World>(*robot_, cfg_.world);
    } catch (const std::exception& e) {
      p.fail("", std::string("the world cannot be built: ") + e.what());
    }
    drivers::sim::SimRobotConfig rc;
    rc.prefix = cfg_.bus_prefix;
    rc.bitrate = cfg_.bitrate;
    rc.data_bitrate = cfg_.data_bitrate;
    rc.watchdog_ns = std::llround(cfg_.device_watchdog_ms * 1e6);
    try {
      devices_ = std::make_unique<wd::WorldDevices>(*world_, rc);
    } catch (const std::exception& e) {
      p.fail("bus_prefix", std::string("cannot create the mocked buses: ") + e.what() +
                               " (is another simulated robot running with this prefix?)");
    }
    try {
      const std::string link =
          cfg_.tactile_link.empty() ? std::string() : drivers::simulated_link_path(cfg_.bus_prefix, cfg_.tactile_link);
      tactile_ = std::make_unique<wd::WorldTactile>(robot_->params(), cfg_.world.seed, link);
    } catch (const std::exception& e) {
      p.fail("tactile_link", e.what());
    }
    if (cfg_.faults) {
      faults_ = std::make_unique<wd::BusFaultInjector>(devices_->robot(), wd::draw_bus_faults(cfg_.bus_faults));
      log_lines(wd::describe(faults_->plan()));
    }
    full_ = std::make_unique<SheetState>();
    if (cfg_.truth_stride > 1) truth_ = std::make_unique<SheetState>();
    state_ = std::make_unique<WorldState>();
    world_out_ = ports.latest_output<WorldState>("world_state", WorldState{});
    const auto no_sheet = std::make_unique<SheetState>();  // the safe value: no sheet (0 x 0 nodes)
    sheet_out_ = ports.latest_output<SheetState>("sheet_truth", *no_sheet);
    shapes_ = std::make_unique<WorldShapes>();
    const auto no_shapes = std::make_unique<WorldShapes>();  // the safe value: no robot in view
    shapes_out_ = ports.latest_output<WorldShapes>("world_shapes", *no_shapes);
    log_lines(wd::describe(cfg_.world.seed, world_->draws()));
  }

  void activate() override { steps_ = 0; }

  Status update(const Cycle& cycle) override {
    devices_->step_rt();
    if (faults_) faults_->tick_rt(world_->state().time_s);
    tactile_->step_rt(world_->state(), cfg_.world.dt_s, devices_->robot(), devices_->device_time_ns());
    *state_ = world_->state();
    state_->timestamp_ns = cycle.time_ns;  // the port's stamp: the loop's clock
    world_out_.write(*state_, cycle.time_ns);
    if (steps_ % static_cast<std::uint64_t>(cfg_.shapes_every_steps) == 0)
      publish_shapes(cycle.time_ns);
    if (steps_++ % static_cast<std::uint64_t>(cfg_.truth_every_steps) == 0) publish_sheet(cycle.time_ns);
    return Status::ok;
  }

  void cleanup() override {
    faults_.reset();  // before the buses it injects into
    tactile_.reset();
    devices_.reset();  // the devices and their buses first: they reference the world
    world_.reset();
    robot_.reset();
  }

 private:
  void publish_shapes(std::int64_t now_ns) noexcept {
    wd::export_shapes_rt(world_->shapes(), *shapes_);
    shapes_->timestamp_ns = now_ns;
    shapes_->step = world_->state().step;
    shapes_out_.write(*shapes_, now_ns);
  }

  void publish_sheet(std::int64_t now_ns) noexcept {
    world_->export_sheet_rt(*full_);
    full_->timestamp_ns = now_ns;
    if (!truth_) {
      sheet_out_.write(*full_, now_ns);
      return;
    }
    // Every stride-th node in u and v: the coarser grid's nodes are the finer grid's.
    const int k = cfg_.truth_stride, W = full_->nodes_u, H = full_->nodes_v;
    SheetState& t = *truth_;
    t.timestamp_ns = now_ns;
    t.step = full_->step;
    t.nodes_u = static_cast<std::uint16_t>((W - 1) / k + 1);
    t.nodes_v = static_cast<std::uint16_t>((H - 1) / k + 1);
    t.width_mm = full_->width_mm;
    t.height_mm = full_->height_mm;
    t.link_count = 0;  // the world's links are not the coarse grid's
    t.crease_count = 0;
    t.fit_error_mm = full_->fit_error_mm;
    t.observations = 0;
    t.rollbacks = full_->rollbacks;
    for (int j = 0; j < t.nodes_v; ++j) {
      for (int i = 0; i < t.nodes_u; ++i) {
        const int from = j * k * W + i * k, to = j * t.nodes_u + i;
        std::memcpy(t.position_mm[to], full_->position_mm[from], sizeof t.position_mm[to]);
        std::memcpy(t.normal[to], full_->normal[from], sizeof t.normal[to]);
      }
    }
    sheet_out_.write(t, now_ns);
  }

  // A long line (the world's draws, the buses' faults) in lines the RT log carries (96
  // characters each), cut after a comma or semicolon.
  void log_lines(const std::string& line) const {
    std::size_t at = 0;
    while (at < line.size()) {
      std::size_t n = std::min<std::size_t>(90, line.size() - at);
      if (at + n < line.size()) {
        const std::size_t comma = line.rfind(", ", at + n), semi = line.rfind("; ", at + n);
        const std::size_t cut = comma == std::string::npos ? semi : (semi == std::string::npos ? comma : std::max(comma, semi));
        if (cut != std::string::npos && cut > at) n = cut + 2 - at;
      }
      log_rt(rt::LogLevel::info, line.substr(at, n).c_str());
      at += n;
    }
  }

  wd::WorldPluginConfig cfg_;
  std::unique_ptr<robot::RobotModel> robot_;
  std::unique_ptr<wd::World> world_;
  std::unique_ptr<wd::WorldDevices> devices_;
  std::unique_ptr<wd::WorldTactile> tactile_;
  std::unique_ptr<wd::BusFaultInjector> faults_;  // faults: true
  std::unique_ptr<SheetState> full_, truth_;
  std::unique_ptr<WorldState> state_;
  std::unique_ptr<WorldShapes> shapes_;
  LatestOutput<WorldState> world_out_;
  LatestOutput<SheetState> sheet_out_;
  LatestOutput<WorldShapes> shapes_out_;
  std::uint64_t steps_ = 0;
};

}  // namespace

CREASE_PLUGIN(SimWorldPlugin, "sim_world", "1.0.0")
