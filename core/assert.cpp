#include "core/assert.h"

#include <cstdio>
#include <cstdlib>

namespace crease::detail {

void demand_failed(const char* cond, const char* msg, const char* file, int line) noexcept {
  std::fprintf(stderr, "crease: internal error at %s:%d: %s (%s)\n", file, line, msg, cond);
  std::fflush(stderr);
  std::abort();
}

}  // namespace crease::detail
