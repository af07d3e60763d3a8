// The simulated link's statuses as a test sees them from outside the loops: each device
// port's oldest age seen (the status's reception time against the cycle that published it),
// the first cycle its health left `ok`, and the contact controllers' first unhealthy cycle, so
// that a run aborted on a device fault names the device, its port and the age at the fault.
// Polled from the test's thread (every millisecond or so); ages come from the values
// themselves, not from when the test looked.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "core/plugin_host.h"
#include "core/port_types/arm.h"
#include "core/port_types/contact.h"
#include "core/port_types/hand.h"
#include "core/port_types/tactile.h"
#include "core/port_types/world_state.h"
#include "rt/latest.h"

namespace crease::test {

class SimLinkWatch {
 public:
  explicit SimLinkWatch(PluginHost& host) {
    add<HandState>(host, "hand_r.state");
    add<HandState>(host, "hand_l.state");
    add<ArmState>(host, "arm_r.state");
    add<ArmState>(host, "arm_l.state");
    add<Tactile>(host, "hand_r.tactile");
    add<ContactState>(host, "contact_r.state");
    add<ContactState>(host, "contact_l.state");
    if (const rt::LatestChannel* ch = host.ports().find_latest("world_state")) world_ = rt::LatestReader<WorldState>(ch);
  }

  void poll() {
    for (Port& p : ports_) p.poll(p);
    if (world_.bound() && world_.poll().is_new()) {
      // How far the world's steps fell behind the wall clock (1 ms a step): a stalled world.
      const WorldState& w = world_.value();
      if (world_step0_ == 0) {
        world_step0_ = w.step;
        world_t0_ns_ = w.timestamp_ns;
      }
      const std::int64_t lag = (w.timestamp_ns - world_t0_ns_) - static_cast<std::int64_t>(w.step - world_step0_) * 1'000'000;
      world_max_jump_ns_ = std::max(world_max_jump_ns_, lag - world_lag_ns_);
      world_lag_ns_ = lag;
    }
  }

  // One line per port: "hand_r.tactile: oldest 12.3 ms, first fault at +4.1 s (age 101 ms)".
  [[nodiscard]] std::string summary() const {
    std::ostringstream o;
    for (const Port& p : ports_) {
      o << p.name << ": oldest " << static_cast<double>(p.max_age_ns) / 1e6 << " ms";
      if (p.extra != 0) o << ", " << p.extra_name << " " << p.extra;
      if (p.bad_at_ns != 0)
        o << ", first bad at +" << static_cast<double>(p.bad_at_ns - first_ns_) / 1e9 << " s (age "
          << static_cast<double>(p.bad_age_ns) / 1e6 << " ms; the world then "
          << static_cast<double>(p.bad_world_lag_ns) / 1e6 << " ms behind)";
      o << "\n";
    }
    o << "world_state: behind the wall clock by " << static_cast<double>(world_lag_ns_) / 1e6
      << " ms, at most " << static_cast<double>(world_max_jump_ns_) / 1e6 << " ms more between two looks\n";
    return o.str();
  }
  // The longest age any hand or arm status or the taxels reached (ns).
  [[nodiscard]] std::int64_t max_age_ns(const std::string& port) const {
    for (const Port& p : ports_)
      if (p.name == port) return p.max_age_ns;
    return -1;
  }
  [[nodiscard]] bool any_bad() const {
    return std::any_of(ports_.begin(), ports_.end(), [](const Port& p) { return p.bad_at_ns != 0; });
  }

 private:
  struct Port {
    std::string name;
    std::int64_t max_age_ns = 0, bad_at_ns = 0, bad_age_ns = 0;
    std::uint64_t extra = 0;  // tactile: overruns; contact: unhealthy cycles seen
    const char* extra_name = "";
    void (*poll)(Port&) = nullptr;
    std::shared_ptr<void> reader;
    std::int64_t* first_ns = nullptr;
    const std::int64_t* world_lag_ns = nullptr;
    std::int64_t bad_world_lag_ns = 0;
  };

  template <class T>
  static void poll_port(Port& p) {
    auto& r = *static_cast<rt::LatestReader<T>*>(p.reader.get());
    const rt::ReadInfo info = r.poll();
    if (!info.is_new()) return;
    const T& v = r.value();
    if (*p.first_ns == 0) *p.first_ns = info.stamp_ns;
    std::int64_t age = 0;
    bool bad = false;
    if constexpr (std::is_same_v<T, Tactile>) {
      age = v.frames != 0 ? v.age_ns : 0;
      bad = v.frames != 0 && v.health == DeviceHealth::fault;
      p.extra = v.overruns;
      p.extra_name = "overruns";
    } else if constexpr (std::is_same_v<T, ContactState>) {
      age = v.timestamp_ns != 0 ? info.stamp_ns - v.timestamp_ns : 0;
      bad = v.timestamp_ns != 0 && v.healthy == 0 && info.stamp_ns - *p.first_ns > 3'000'000'000;
      if (bad) ++p.extra;
      p.extra_name = "unhealthy samples";
    } else {
      age = v.timestamp_ns != 0 ? info.stamp_ns - v.timestamp_ns : 0;
      bad = v.timestamp_ns != 0 && v.health == DeviceHealth::fault;
    }
    p.max_age_ns = std::max(p.max_age_ns, age);
    if (bad && p.bad_at_ns == 0) {
      p.bad_at_ns = info.stamp_ns;
      p.bad_age_ns = age;
      p.bad_world_lag_ns = *p.world_lag_ns;
    }
  }

  template <class T>
  void add(PluginHost& host, const std::string& name) {
    const rt::LatestChannel* ch = host.ports().find_latest(name);
    if (ch == nullptr) return;
    Port p;
    p.name = name;
    p.reader = std::make_shared<rt::LatestReader<T>>(ch);
    p.poll = &poll_port<T>;
    p.first_ns = &first_ns_;
    p.world_lag_ns = &world_lag_ns_;
    ports_.push_back(std::move(p));
  }

  std::vector<Port> ports_;
  rt::LatestReader<WorldState> world_;
  std::uint64_t world_step0_ = 0;
  std::int64_t world_t0_ns_ = 0, world_lag_ns_ = 0, world_max_jump_ns_ = 0;
  std::int64_t first_ns_ = 0;
};

}  // namespace crease::test
