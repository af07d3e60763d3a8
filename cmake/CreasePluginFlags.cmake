# crease_plugin_flags(TARGET): what makes a MODULE a Crease plugin, the same in the tree and for
# plugins built against the installed SDK (lib/cmake/Crease): C++20, hidden visibility (only
# the CREASE_PLUGIN entry point is exported), -fno-gnu-unique (GCC: so dlclose really unloads
# it and a hot-swap loads the new code; clang emits no unique symbols), and no undefined
# symbols at link time.
function(crease_plugin_flags target)
  target_compile_features(${target} PRIVATE cxx_std_20)
  set_target_properties(${target} PROPERTIES
    CXX_EXTENSIONS OFF
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-fno-gnu-unique>)
  target_link_options(${target} PRIVATE -Wl,--no-undefined)
endfunction()
