// Port payload `Gain` of the example: a trivially copyable struct that names itself.
#pragma once

#include <cmath>
#include <cstdint>

struct Gain {
  static constexpr char kPortType[] = "example.Gain";
  static constexpr std::uint32_t kPortVersion = 1;
  double value;
  bool all_finite() const { return std::isfinite(value); }  // optional: NaN => fault
};
