#include "plugins/sim_world/world_tactile.h"

#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace crease::world {

namespace fs = std::filesystem;

WorldTactile::WorldTactile(const robot::RobotParams& robot, std::uint64_t seed, const std::string& link_path) {
  for (int s = 0; s < 2; ++s) {
    const robot::TactileParams& t = robot.side(static_cast<robot::Side>(s)).tactile;
    model_[s] = std::make_unique<TactileModel>(t, seed + static_cast<std::uint64_t>(s));
    if (t.kind == robot::TactileKind::taxel_matrix && taxel_side_ < 0) taxel_side_ = s;
    if (t.kind == robot::TactileKind::pst && pst_side_ < 0) pst_side_ = s;
  }
  if (link_path.empty() || taxel_side_ < 0) return;
  pty_ = std::make_unique<drivers::PtyPair>();
  std::error_code ec;
  if (fs::is_symlink(fs::symlink_status(link_path, ec))) {
    if (fs::exists(link_path, ec)) {
      throw std::runtime_error("the tactile link " + link_path + " is taken (-> " + fs::read_symlink(link_path, ec).string() +
                               ")");
    }
    fs::remove(link_path, ec);  // a dangling link a dead robot left
  }
  fs::create_symlink(pty_->slave_path(), link_path, ec);
  if (ec) throw std::runtime_error("cannot create the tactile link " + link_path + ": " + ec.message());
  link_path_ = link_path;
  device_ = std::make_unique<drivers::sim::SimTactile>(pty_->master_fd(), true);
}

WorldTactile::~WorldTactile() {
  device_.reset();
  if (!link_path_.empty()) {
    std::error_code ec;
    fs::remove(link_path_, ec);
  }
}

void WorldTactile::step_rt(const WorldState& state, double dt_s, drivers::sim::SimRobot& robot,
                           std::int64_t device_ns) noexcept {
  if (pst_side_ >= 0) {
    model_[pst_side_]->pst_rt(state.hand[pst_side_], dt_s, pst_);
    for (int k = 0; k < WorldHand::kFingertips; ++k) robot.hand(pst_side_).set_pressure(k, pst_[k]);
  }
  if (taxel_side_ >= 0) {
    model_[taxel_side_]->taxels_rt(state.hand[taxel_side_], taxels_);
    if (device_) {
      device_->set_pressures(taxels_);
      device_->step(device_ns);
    }
  }
}

}  // namespace crease::world
