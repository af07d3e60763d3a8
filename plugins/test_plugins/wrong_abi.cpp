// Test plugin built against a future ABI: the host must refuse it with a clear message.
#include "core/abi.h"

extern "C" CREASE_EXPORT const crease_plugin_descriptor* crease_plugin_entry(void) {
  static const crease_plugin_descriptor d{99u, sizeof(crease_plugin_descriptor),
                                          "test_wrong_abi", "1.0.0", nullptr, nullptr, nullptr, nullptr, nullptr,
                                          nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
  return &d;
}
