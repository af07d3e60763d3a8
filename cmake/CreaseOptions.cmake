# The one place that sets warnings and sanitizers for every Crease target.

set(CREASE_SANITIZE "" CACHE STRING "Sanitizer build: '', 'address' (ASan+UBSan) or 'thread' (TSan)")
set_property(CACHE CREASE_SANITIZE PROPERTY STRINGS "" address thread)

add_library(crease_options INTERFACE)
target_compile_options(crease_options INTERFACE
  -Wall -Wextra -Wpedantic -Werror -Wvla -Wimplicit-fallthrough -Wno-missing-field-initializers)

if(CREASE_SANITIZE STREQUAL "address")
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
  add_compile_definitions(CREASE_SANITIZER_ADDRESS=1)
  # GCC 12 at -O1 with ASan reports std::regex's and std::function's members as maybe used
  # uninitialised (its documented false positives under -fsanitize=address); the release and
  # TSan builds keep the warning.
  target_compile_options(crease_options INTERFACE -Wno-maybe-uninitialized)
elseif(CREASE_SANITIZE STREQUAL "thread")
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
  add_compile_definitions(CREASE_SANITIZER_THREAD=1)
elseif(NOT CREASE_SANITIZE STREQUAL "")
  message(FATAL_ERROR "CREASE_SANITIZE must be '', 'address' or 'thread', not '${CREASE_SANITIZE}'")
endif()
