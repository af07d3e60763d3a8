#include "plugins/sim_world/world_tactile.h"

#include <unistd.h>

namespace crease::world {

WorldTactile::WorldTactile(const robot::RobotParams& robot, std::uint64_t seed, const std::string& link_path) {
  for (int s = 0; s < 2; ++s) {
    const robot::TactileParams& t = robot.side(static_cast<robot::Side>(s)).tactile;
    model_[s] = std::make_unique<TactileModel>(t, seed + static_cast<std::uint64_t>(s));
    if (t.kind == robot::TactileKind::taxel_matrix && taxel_side_ < 0) taxel_side_ = s;
    if (t.kind == robot::TactileKind::pst && pst_side_ < 0) pst_side_ = s;
  }
  if (link_path.empty() || taxel_side_ < 0) return;
  listener_ = std::make_unique<drivers::UnixLinkListener>(link_path);
  link_path_ = link_path;
  device_ = std::make_unique<drivers::sim::SimTactile>(-1, true);
}

WorldTactile::~WorldTactile() {
  device_.reset();
  if (peer_ >= 0) ::close(peer_);
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
      // The connection's peer gone (looked at every 8 steps): serve the next one waiting.
      if (peer_ >= 0 && ++steps_ % 8 == 0 && drivers::unix_link_hung_up(peer_)) {
        ::close(peer_);
        peer_ = -1;
      }
      if (peer_ < 0) {
        const int fd = listener_->accept_rt();
        if (fd >= 0) {
          peer_ = fd;
          device_->reset_link(fd);
          connections_.fetch_add(1, std::memory_order_relaxed);
        }
      }
      if (peer_ >= 0) {
        device_->set_pressures(taxels_);
        device_->step(device_ns);
      }
    }
  }
}

}  // namespace crease::world
