# crease_job_target(NAME CONFIGS files... [TOOLS targets...] [EXTRA targets...])
# Target NAME: what a run of the CONFIGS needs and nothing else (no test): the TOOLS (creased,
# creasectl, ...), every plugin library the CONFIGS load (their `library:` lines, read at
# configure time; CMake re-configures when one changes) and EXTRA (e.g. the plugin a documented
# hot-swap loads). A `library:` naming no plugin target is a configure error.
function(crease_job_target name)
  cmake_parse_arguments(M "" "" "CONFIGS;TOOLS;EXTRA" ${ARGN})
  set(plugins)
  foreach(config ${M_CONFIGS})
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${config})
    file(STRINGS ${config} lines REGEX "^[ \t-]*library:[ \t]*[A-Za-z0-9_]+")
    foreach(line ${lines})
      string(REGEX REPLACE "^[ \t-]*library:[ \t]*([A-Za-z0-9_]+).*" "\\1" lib "${line}")
      if(NOT TARGET ${lib})
        message(FATAL_ERROR "${config}: library '${lib}' is no plugin target of this build")
      endif()
      list(APPEND plugins ${lib})
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES plugins)
  add_custom_target(${name})
  add_dependencies(${name} ${M_TOOLS} ${plugins} ${M_EXTRA})
endfunction()

# crease_main_job_target(CONFIG [TOOLS targets...] [EXTRA targets...]): target `main-job`, what
# tools/run needs.
function(crease_main_job_target config)
  crease_job_target(main-job CONFIGS ${config} ${ARGN})
endfunction()
