/* The plugin ABI: the one C boundary between the host and a plugin library.
 *
 * A plugin library exports one symbol, `crease_plugin_entry`, which returns a pointer to a
 * static descriptor. The host refuses a library whose abi_version differs from
 * CREASE_PLUGIN_ABI_VERSION or whose struct_size is smaller than the host's descriptor.
 * No exception crosses this boundary: the C++ adapters in plugin.h catch them and return a
 * status. Strings in the descriptor live in the library; the host copies them.
 *
 * Return codes (int32_t): 0 ok, 1 degraded, 2 fault, 3 threw (an exception was caught),
 * 4 device fault (a driver's device is gone; the plugin stays scheduled: core/status.h). A host
 * that predates code 4 takes it as an unknown code, i.e. a fault.
 */
#ifndef CREASE_CORE_ABI_H
#define CREASE_CORE_ABI_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* 2: the optional write phase (crease_plugin_descriptor.write). */
#define CREASE_PLUGIN_ABI_VERSION 2u
#define CREASE_PLUGIN_ENTRY_SYMBOL "crease_plugin_entry"
#define CREASE_EXPORT __attribute__((visibility("default")))

/* The cycle a plugin's update runs in. Times are CLOCK_MONOTONIC ns. */
typedef struct crease_cycle {
  uint64_t index;      /* the loop's cycle number (counts deadlines; gaps after skipped periods) */
  int64_t time_ns;     /* the cycle's scheduled time: stamp outputs with it */
  int64_t period_ns;   /* the loop's period */
  int64_t wake_ns;     /* when the loop actually woke */
} crease_cycle;

typedef struct crease_plugin_descriptor {
  uint32_t abi_version;   /* CREASE_PLUGIN_ABI_VERSION */
  uint32_t struct_size;   /* sizeof(crease_plugin_descriptor) as the plugin saw it */
  const char* name;       /* plugin type name, e.g. "sheet_model" */
  const char* version;    /* plugin version, e.g. "1.2.0" */

  /* non-RT, required. Returns the instance or NULL. */
  void* (*create)(void);
  /* non-RT, required. */
  void (*destroy)(void* self);
  /* non-RT, required. ctx is the host's crease::ConfigureContext (C++; its layout is part of
   * the ABI version). Parses parameters, binds ports, allocates. On failure writes a message
   * into error (NUL-terminated, at most error_size bytes) and returns 2. */
  int32_t (*configure)(void* self, void* ctx, char* error, size_t error_size);
  /* non-RT, required. Called before the instance is scheduled. Must not write outputs. */
  int32_t (*activate)(void* self, char* error, size_t error_size);
  /* RT, required. Once per cycle of the instance's loop: read inputs (a driver: the bus), compute,
   * write outputs. */
  int32_t (*update)(void* self, const crease_cycle* cycle);
  /* non-RT, required. Called after the instance left the schedule. */
  int32_t (*deactivate)(void* self);
  /* non-RT, required. Releases what configure acquired. */
  int32_t (*cleanup)(void* self);
  /* RT-safe, required (may write nothing). At a hot-swap cycle boundary: serialises the state
   * to carry into buf (capacity cap); returns the bytes written, or SIZE_MAX if cap is too small. */
  size_t (*save_state)(void* self, void* buf, size_t cap);
  /* RT-safe, required. Takes over state written by save_state of the previous version.
   * Returns 0, or 2 when the bytes are not understood (the instance then starts fresh). */
  int32_t (*load_state)(void* self, const void* buf, size_t len);
  /* non-RT, required. Validates a new value for a tunable parameter; 0 = accept. */
  int32_t (*validate_param)(void* self, const char* key, double value, char* error, size_t error_size);
  /* RT, optional (NULL: no write phase). Once per cycle, after every instance of the loop ran
   * update: sends what this cycle computed (a driver: the commands other plugins wrote in this
   * cycle's update), as ros2_control's write() after update(). Return codes as update. */
  int32_t (*write)(void* self, const crease_cycle* cycle);
} crease_plugin_descriptor;

typedef const crease_plugin_descriptor* (*crease_plugin_entry_fn)(void);

#ifdef __cplusplus
}
#endif

#endif /* CREASE_CORE_ABI_H */
