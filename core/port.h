// Port payload types and the typed port ends a plugin holds.
//
// A port is a named, typed, single-writer channel owned by the host's PortRegistry:
//  - `latest` carries state (rt::LatestChannel): readers get the newest value and whether it is new;
//  - `queue` carries events (rt::QueueChannel): bounded, overflow counted, never blocks.
// A payload type is a trivially copyable struct of fixed capacity that names itself:
//   struct HandCommand {
//     static constexpr char kPortType[] = "crease.HandCommand";
//     static constexpr std::uint32_t kPortVersion = 1;
//     double target_rad[20];
//     bool all_finite() const;   // optional: checked on every write
//   };
// Type name, version and size are checked when a port is bound; a mismatch is a PortError
// naming both ends.
#pragma once

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "rt/latest.h"
#include "rt/queue.h"

namespace crease {

// latest and queue carry payloads (below); frames carries camera images (core/frames, bound
// through PortBinder::frames_output / frames_input).
enum class PortKind : std::uint8_t { latest, queue, frames };

// Runtime identity of a payload type (the registry copies the name).
struct PortType {
  const char* name;
  std::uint32_t version;
  std::size_t size;
};

template <class T>
concept PortPayload = std::is_trivially_copyable_v<T> && requires {
  { T::kPortType } -> std::convertible_to<const char*>;
  { T::kPortVersion } -> std::convertible_to<std::uint32_t>;
};

template <PortPayload T>
constexpr PortType port_type_of() noexcept {
  return PortType{T::kPortType, T::kPortVersion, sizeof(T)};
}

template <class T>
[[nodiscard]] inline bool payload_is_finite(const T& v) noexcept {
  if constexpr (requires { { v.all_finite() } -> std::convertible_to<bool>; }) {
    return v.all_finite();
  } else {
    return true;
  }
}

namespace detail {
// Per-instance flags the loop checks after each update (owned by the host, RT-thread only).
struct OutputFlags {
  bool non_finite = false;  // an output write carried a NaN or infinity (and was not published)
};
}  // namespace detail

// The writing end of a latest port. RT-safe.
template <PortPayload T>
class LatestOutput {
 public:
  LatestOutput() = default;
  LatestOutput(rt::LatestChannel* ch, detail::OutputFlags* flags) noexcept : ch_(ch), flags_(flags) {}
  // Publishes v stamped with stamp_ns (use cycle.time_ns). A non-finite payload is not published:
  // it is flagged, and the host then faults the plugin and drives its outputs safe.
  void write(const T& v, std::int64_t stamp_ns) noexcept {
    if (!payload_is_finite(v)) {
      flags_->non_finite = true;
      return;
    }
    ch_->write(&v, stamp_ns);
  }
  [[nodiscard]] bool bound() const noexcept { return ch_ != nullptr; }

 private:
  rt::LatestChannel* ch_ = nullptr;
  detail::OutputFlags* flags_ = nullptr;
};

// The reading end of a latest port. It keeps the newest value itself: call poll() once per
// cycle, then use value(), which holds the newest value also on cycles when nothing new
// arrived (a command written once stays the command).
//   const auto info = in_.poll();          // RT-safe
//   if (!info.has_data()) return Status::degraded;   // never written: value() is T{}
//   use(in_.value());                      // info.is_new() tells whether it changed
// Binding allocates (configure time); the end is move-only.
template <PortPayload T>
class LatestInput {
 public:
  LatestInput() = default;
  explicit LatestInput(const rt::LatestChannel* ch) : reader_(ch) {}
  // RT-safe. Takes the newest value into value(); flow says none / old (value() unchanged) / new.
  rt::ReadInfo poll() noexcept { return reader_.poll(); }
  // The newest value taken (T{} before the first). Stable until the next poll().
  [[nodiscard]] const T& value() const noexcept { return reader_.value(); }
  [[nodiscard]] bool has_value() const noexcept { return reader_.has_value(); }
  // Sequence number and timestamp of the value held.
  [[nodiscard]] const rt::ReadInfo& held() const noexcept { return reader_.held(); }
  [[nodiscard]] bool bound() const noexcept { return reader_.bound(); }

 private:
  rt::LatestReader<T> reader_;
};

// The writing end of a queue port. RT-safe.
template <PortPayload T>
class QueueOutput {
 public:
  QueueOutput() = default;
  QueueOutput(rt::QueueChannel* ch, detail::OutputFlags* flags) noexcept : ch_(ch), flags_(flags) {}
  // False when the queue is full (the event is dropped and counted) or the event is non-finite.
  [[nodiscard]] bool try_push(const T& v) noexcept {
    if (!payload_is_finite(v)) {
      flags_->non_finite = true;
      return false;
    }
    return ch_->try_push(&v);
  }
  [[nodiscard]] bool bound() const noexcept { return ch_ != nullptr; }

 private:
  rt::QueueChannel* ch_ = nullptr;
  detail::OutputFlags* flags_ = nullptr;
};

// The reading end of a queue port (one reader per queue). RT-safe.
template <PortPayload T>
class QueueInput {
 public:
  QueueInput() = default;
  explicit QueueInput(rt::QueueChannel* ch) noexcept : ch_(ch) {}
  [[nodiscard]] bool try_pop(T& out) noexcept { return ch_->try_pop(&out); }
  [[nodiscard]] bool bound() const noexcept { return ch_ != nullptr; }

 private:
  rt::QueueChannel* ch_ = nullptr;
};

}  // namespace crease
