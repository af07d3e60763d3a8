// contact_controller: C_contact (seed 000 Eq. 5) for one hand in the control loop, ordered
// after the hand's driver and before the force controller. Reads hand_state (and hand_command
// for the commanded targets, and tactile for the right hand's taxels), publishes contact_state
// and contact_event (core/port_types/contact.h). It writes no command. README.md.
#include <cstring>

#include "core/plugin.h"
#include "core/port_types/contact.h"
#include "core/port_types/hand.h"
#include "core/port_types/tactile.h"
#include "plugins/contact_controller/contact_detector.h"
#include "plugins/contact_controller/contact_params.h"

namespace crease::contact {
namespace {

class ContactController final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    detector_ = ContactDetector(read_contact_config(p));
    read_command_ = p.get<bool>("read_command", true);
    hand_ = ports.latest_input<HandState>("hand_state");
    if (read_command_) command_ = ports.latest_input<HandCommand>("hand_command");
    if (detector_.config().tactile == TactileSource::taxels) tactile_ = ports.latest_input<Tactile>("tactile");
    state_ = ports.latest_output<ContactState>("contact_state", ContactState{});
    events_ = ports.queue_output<ContactEvent>("contact_event", 64);  // onsets and releases: a few per second
  }

  Status update(const Cycle& c) override {
    const auto info = hand_.poll();
    ContactInputs in;
    in.time_ns = c.time_ns;
    in.dt_s = static_cast<double>(c.period_ns) * 1e-9;
    in.hand = info.has_data() ? &hand_.value() : nullptr;
    in.hand_new = info.is_new();
    if (command_.bound() && command_.poll().has_data()) in.command = &command_.value();
    if (tactile_.bound() && tactile_.poll().has_data()) in.tactile = &tactile_.value();
    ContactState out;
    ContactEvent ev;
    if (detector_.step_rt(in, out, ev)) {
      if (!events_.try_push(ev)) ++events_dropped_;
    }
    state_.write(out, c.time_ns);
    return out.healthy != 0 ? Status::ok : Status::degraded;
  }

  std::size_t save_state(std::span<std::byte> out) const noexcept override {
    const auto& s = detector_.state();
    if (out.size() < sizeof(s)) return SIZE_MAX;
    std::memcpy(out.data(), &s, sizeof(s));
    return sizeof(s);
  }
  bool load_state(std::span<const std::byte> in) noexcept override {
    ContactDetector::State s;
    if (in.size() != sizeof(s)) return false;
    std::memcpy(&s, in.data(), sizeof(s));
    detector_.restore(s);
    return true;
  }

 private:
  ContactDetector detector_{ContactConfig{}};
  bool read_command_ = true;
  LatestInput<HandState> hand_;
  LatestInput<HandCommand> command_;
  LatestInput<Tactile> tactile_;
  LatestOutput<ContactState> state_;
  QueueOutput<ContactEvent> events_;
  std::uint64_t events_dropped_ = 0;
};

}  // namespace
}  // namespace crease::contact

CREASE_PLUGIN(crease::contact::ContactController, "contact_controller", "1.0.0")
