# crease_main_job_target(CONFIG [TOOLS targets...] [EXTRA targets...])
# Target `main-job`: what tools/run needs and nothing else (no test): the TOOLS (creased,
# creasectl, ...), every plugin library CONFIG loads (its `library:` lines, read at configure
# time; CMake re-configures when CONFIG changes) and EXTRA (e.g. the plugin a documented
# hot-swap loads). A `library:` naming no plugin target is a configure error.
function(crease_main_job_target config)
  cmake_parse_arguments(M "" "" "TOOLS;EXTRA" ${ARGN})
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${config})
  file(STRINGS ${config} lines REGEX "^[ \t-]*library:[ \t]*[A-Za-z0-9_]+")
  set(plugins)
  foreach(line ${lines})
    string(REGEX REPLACE "^[ \t-]*library:[ \t]*([A-Za-z0-9_]+).*" "\\1" lib "${line}")
    if(NOT TARGET ${lib})
      message(FATAL_ERROR "${config}: library '${lib}' is no plugin target of this build")
    endif()
    list(APPEND plugins ${lib})
  endforeach()
  list(REMOVE_DUPLICATES plugins)
  add_custom_target(main-job)
  add_dependencies(main-job ${M_TOOLS} ${plugins} ${M_EXTRA})
endfunction()
