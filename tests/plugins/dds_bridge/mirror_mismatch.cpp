// Compiled (syntax only) by ctest once per MISMATCH value: 0 must compile; every other value is
// an IDL/C++ difference CREASE_DDS_MIRROR must refuse (tests/plugins/dds_bridge/CMakeLists.txt).
#include <cstdint>

#include "plugins/dds_bridge/mirror.h"

namespace cpp {
enum class Health : std::uint8_t { ok, fault };
struct State {
  std::int64_t stamp_ns = 0;
  float position[4] = {};
  std::uint8_t fresh = 0;
  Health health = Health::ok;
#if MISMATCH == 2
  std::uint8_t added_in_padding = 0;  // fits the padding before `sent`: same size
#endif
  std::uint64_t sent = 0;
};
}  // namespace cpp

extern "C" {
struct c_State {
  int64_t stamp_ns;
#if MISMATCH == 3
  double position[4];  // another type
#elif MISMATCH == 4
  float position[5];  // another extent
#else
  float position[4];
#endif
#if MISMATCH == 5
  uint8_t health;  // order swapped
  uint8_t fresh;
#else
  uint8_t fresh;
  uint8_t health;
#endif
  uint64_t sent;
#if MISMATCH == 1
  uint32_t added_to_idl;  // only in the IDL
#endif
};
}

#define STATE_FIELDS(FIRST, NEXT) FIRST(stamp_ns) NEXT(position) NEXT(fresh) NEXT(health) NEXT(sent)
CREASE_DDS_MIRROR(cpp::State, c_State, STATE_FIELDS)

int main() {
  cpp::State s;
  c_State c{};
  {
    const auto& src = s;
    auto& dst = c;
    STATE_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
  }
  return static_cast<int>(c.sent);
}
