#include "plugins/robot_model/tool_chain.h"

#include "core/assert.h"

namespace crease::robot {

ToolChain::ToolChain(std::string tip, const KDL::Chain& chain, std::vector<JointSource> sources)
    : tip_(std::move(tip)),
      chain_(std::make_unique<KDL::Chain>(chain)),
      fk_(std::make_unique<KDL::ChainFkSolverPos_recursive>(*chain_)),
      q_(chain.getNrOfJoints()),
      sources_(std::move(sources)) {
  // RobotModel::make_chain builds the sources from the validated model (a bad URDF or parameter
  // file fails there, naming the file, line and joint): a mismatch here is a bug.
  CREASE_DEMAND(sources_.size() == chain_->getNrOfJoints(),
                "ToolChain: one source per chain joint");
  for (const auto& s : sources_) {
    const int n = s.kind == JointSource::arm ? kArmJoints : kHandJoints;
    CREASE_DEMAND(s.index >= 0 && s.index < n, "ToolChain: a source index out of its joint range");
  }
}

void ToolChain::chain_angles(ArmAngles arm, HandAngles hand, KDL::JntArray& q) const noexcept {
  for (std::size_t j = 0; j < sources_.size(); ++j) {
    const JointSource& s = sources_[j];
    const double master = s.kind == JointSource::arm ? arm[s.index] : hand[s.index];
    q(static_cast<unsigned>(j)) = s.multiplier * master + s.offset;
  }
}

bool ToolChain::pose_m(ArmAngles arm, HandAngles hand, KDL::Frame& out) noexcept {
  chain_angles(arm, hand, q_);
  return fk_->JntToCart(q_, out) >= 0;
}

}  // namespace crease::robot
