// Writing a Crease plugin: derive from crease::Plugin, register with one line.
//
//   class Counter final : public crease::Plugin {
//    public:
//     void configure(const crease::Params& p, crease::PortBinder& ports) override {
//       step_ = p.get<double>("step", 1.0);
//       out_ = ports.latest_output<Count>("count", Count{});
//     }
//     crease::Status update(const crease::Cycle& c) override {
//       out_.write(Count{n_ += step_}, c.time_ns);
//       return crease::Status::ok;
//     }
//    private: ...
//   };
//   CREASE_PLUGIN(Counter, "counter", "1.0.0")
//
// Where each hook runs:
//   configure   non-RT  parse parameters (Params throws ConfigError), bind ports, allocate all
//   activate    non-RT  before the instance is scheduled; must not write outputs
//   update      RT      every cycle: no allocation, lock, blocking call, exception or logging
//                       (use log_rt); return ok / degraded / fault
//   write       RT      optional: declare `crease::Status write(const crease::Cycle&)` (not a
//                       virtual of Plugin) to get a write phase: called every cycle after every
//                       instance of the loop ran update, so a driver reads its bus in update and
//                       sends, in write, the command a controller computed in this same cycle
//   deactivate  non-RT  after the instance left the schedule
//   cleanup     non-RT  release what configure acquired
//   save_state  RT-safe at a hot-swap boundary: copy the state the next version takes over
//   load_state  RT-safe at that boundary, on the new version
// The loop (not the plugin) owns the clock and the thread. An exception thrown by any hook is
// caught at the boundary: from configure/activate it is a load error, from update a fault.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <concepts>
#include <exception>
#include <span>
#include <string>
#include <string_view>

#include "core/abi.h"
#include "core/errors.h"
#include "core/params.h"
#include "core/port_binder.h"
#include "core/status.h"
#include "rt/clock.h"
#include "rt/log_queue.h"

namespace crease {

using Cycle = crease_cycle;

// What the host hands to the configure adapter (ABI version 1 layout).
struct ConfigureContext {
  const Params* params = nullptr;
  PortBinder* ports = nullptr;
};

class Plugin {
 public:
  virtual ~Plugin() = default;

  virtual void configure(const Params& params, PortBinder& ports) = 0;
  virtual void activate() {}
  virtual Status update(const Cycle& cycle) = 0;
  virtual void deactivate() {}
  virtual void cleanup() {}
  // Bytes written into out, or SIZE_MAX when out is too small. Default: no state carried.
  virtual std::size_t save_state(std::span<std::byte> out) const noexcept {
    (void)out;
    return 0;
  }
  // False when the bytes are not understood (the instance then starts fresh).
  virtual bool load_state(std::span<const std::byte> in) noexcept {
    (void)in;
    return true;
  }
  // Non-RT. An empty string accepts a new value for a tunable (already checked against its range).
  virtual std::string validate_param(std::string_view key, double value) {
    (void)key;
    (void)value;
    return {};
  }

  // The instance name from the configuration (valid from configure on).
  [[nodiscard]] const std::string& instance_name() const noexcept { return instance_; }

  // Internal: the adapter calls this before configure.
  void attach_host(const ConfigureContext& ctx) noexcept {
    instance_ = ctx.ports->instance();
    log_ = ctx.ports->log_queue();
  }

 protected:
  // RT-safe logging: pushes a fixed-size record; a non-RT thread formats it.
  void log_rt(rt::LogLevel level, const char* text) const noexcept {
    if (log_ != nullptr) log_->try_log(level, instance_.c_str(), text, rt::now_ns());
  }
  void log_rt(rt::LogLevel level, const char* text, std::int64_t value) const noexcept {
    if (log_ != nullptr) log_->try_log(level, instance_.c_str(), text, rt::now_ns(), value);
  }

 private:
  std::string instance_;
  rt::RtLogQueue* log_ = nullptr;
};

namespace detail {

inline void copy_error(char* dst, std::size_t n, const char* msg) noexcept {
  if (dst == nullptr || n == 0) return;
  std::snprintf(dst, n, "%s", msg);
}

// Capture-less adapters from the C descriptor to the C++ class (MuJoCo's plugin pattern).
template <class P>
struct Adapter {
  static void* create() noexcept {
    try {
      return new P();
    } catch (...) {
      return nullptr;
    }
  }
  static void destroy(void* self) noexcept { delete static_cast<P*>(self); }
  static std::int32_t configure(void* self, void* ctx, char* err, std::size_t n) noexcept {
    try {
      const auto* c = static_cast<const ConfigureContext*>(ctx);
      static_cast<P*>(self)->attach_host(*c);
      static_cast<P*>(self)->configure(*c->params, *c->ports);
      return 0;
    } catch (const std::exception& e) {
      copy_error(err, n, e.what());
    } catch (...) {
      copy_error(err, n, "configure threw a non-standard exception");
    }
    return 2;
  }
  static std::int32_t activate(void* self, char* err, std::size_t n) noexcept {
    try {
      static_cast<P*>(self)->activate();
      return 0;
    } catch (const std::exception& e) {
      copy_error(err, n, e.what());
    } catch (...) {
      copy_error(err, n, "activate threw a non-standard exception");
    }
    return 2;
  }
  static std::int32_t update(void* self, const crease_cycle* cycle) noexcept {
    try {
      return static_cast<std::int32_t>(static_cast<P*>(self)->update(*cycle));
    } catch (...) {
      return 3;
    }
  }
  static std::int32_t write(void* self, const crease_cycle* cycle) noexcept {
    try {
      return static_cast<std::int32_t>(static_cast<P*>(self)->write(*cycle));
    } catch (...) {
      return 3;
    }
  }
  static std::int32_t deactivate(void* self) noexcept {
    try {
      static_cast<P*>(self)->deactivate();
      return 0;
    } catch (...) {
      return 2;
    }
  }
  static std::int32_t cleanup(void* self) noexcept {
    try {
      static_cast<P*>(self)->cleanup();
      return 0;
    } catch (...) {
      return 2;
    }
  }
  static std::size_t save_state(void* self, void* buf, std::size_t cap) noexcept {
    return static_cast<const P*>(self)->save_state(std::span<std::byte>(static_cast<std::byte*>(buf), cap));
  }
  static std::int32_t load_state(void* self, const void* buf, std::size_t len) noexcept {
    return static_cast<P*>(self)->load_state(std::span<const std::byte>(static_cast<const std::byte*>(buf), len)) ? 0 : 2;
  }
  static std::int32_t validate_param(void* self, const char* key, double value, char* err, std::size_t n) noexcept {
    try {
      const std::string why = static_cast<P*>(self)->validate_param(key, value);
      if (why.empty()) return 0;
      copy_error(err, n, why.c_str());
    } catch (const std::exception& e) {
      copy_error(err, n, e.what());
    } catch (...) {
      copy_error(err, n, "validate_param threw");
    }
    return 2;
  }
};

// A plugin has a write phase when it declares `Status write(const Cycle&)`.
template <class P>
concept HasWritePhase = requires(P& p, const Cycle& c) {
  { p.write(c) } -> std::same_as<Status>;
};

template <class P>
constexpr auto write_hook() noexcept -> std::int32_t (*)(void*, const crease_cycle*) {
  if constexpr (HasWritePhase<P>) {
    return &Adapter<P>::write;
  } else {
    return nullptr;
  }
}

template <class P>
const crease_plugin_descriptor* descriptor_for(const char* name, const char* version) noexcept {
  static const crease_plugin_descriptor d{
      CREASE_PLUGIN_ABI_VERSION,  sizeof(crease_plugin_descriptor),
      name,                       version,
      &Adapter<P>::create,        &Adapter<P>::destroy,
      &Adapter<P>::configure,     &Adapter<P>::activate,
      &Adapter<P>::update,        &Adapter<P>::deactivate,
      &Adapter<P>::cleanup,       &Adapter<P>::save_state,
      &Adapter<P>::load_state,    &Adapter<P>::validate_param,
      write_hook<P>()};
  return &d;
}

}  // namespace detail
}  // namespace crease

// Registers a plugin class. One per library.
#define CREASE_PLUGIN(Class, name, version)                                                   \
  extern "C" CREASE_EXPORT const crease_plugin_descriptor* crease_plugin_entry(void) {       \
    static_assert(std::is_base_of_v<::crease::Plugin, Class>, "plugins derive from crease::Plugin"); \
    return ::crease::detail::descriptor_for<Class>(name, version);                            \
  }
