// Test library without the plugin entry point: the host must refuse it.
extern "C" __attribute__((visibility("default"))) int crease_not_a_plugin(void) { return 42; }
