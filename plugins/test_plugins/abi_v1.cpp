// Test plugin built for ABI 1 (before the write phase): its descriptor has the old layout. The
// host must refuse it with a message naming both ABI versions, not call into it.
#include <stddef.h>
#include <stdint.h>

#include "core/abi.h"

namespace {
struct DescriptorV1 {  // crease_plugin_descriptor as ABI 1 laid it out
  uint32_t abi_version;
  uint32_t struct_size;
  const char* name;
  const char* version;
  void* hooks[10];  // create .. validate_param
};
}  // namespace

extern "C" CREASE_EXPORT const crease_plugin_descriptor* crease_plugin_entry(void) {
  static const DescriptorV1 d{1u, sizeof(DescriptorV1), "test_abi_v1", "1.0.0", {}};
  return reinterpret_cast<const crease_plugin_descriptor*>(&d);
}
