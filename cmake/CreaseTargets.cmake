# Helpers that every folder uses to declare plugins and tests.

find_package(doctest REQUIRED)
find_package(Threads REQUIRED)

include(CreasePluginFlags)

# crease_plugin(NAME SOURCES... [LIBS ...] [NO_INSTALL])
# A dlopen'able MODULE with the plugin flags of CreasePluginFlags.cmake. Output:
# ${CREASE_PLUGIN_DIR}/lib<NAME>.so; installed into lib/crease/plugins unless NO_INSTALL (the
# framework's own test plugins), with a run path to the installed lib/.
function(crease_plugin name)
  cmake_parse_arguments(P "NO_INSTALL" "" "SOURCES;LIBS" ${ARGN})
  add_library(${name} MODULE ${P_SOURCES})
  target_link_libraries(${name} PRIVATE crease_core crease_options ${P_LIBS})
  crease_plugin_flags(${name})
  set_target_properties(${name} PROPERTIES
    LIBRARY_OUTPUT_DIRECTORY ${CREASE_PLUGIN_DIR}
    INSTALL_RPATH "$ORIGIN/../..")
  if(NOT P_NO_INSTALL)
    install(TARGETS ${name} LIBRARY DESTINATION ${CREASE_INSTALL_PLUGINDIR} COMPONENT runtime)
  endif()
  set_property(GLOBAL APPEND PROPERTY CREASE_ALL_PLUGINS ${name})
endfunction()

# crease_test(NAME SOURCES... [LIBS ...] [LABELS ...] [DEPENDS targets] [TIMEOUT s])
# One doctest executable registered with ctest. NAME mirrors the source path
# (tests/rt/latest_test.cpp -> rt.latest). Labels: unit, hil, slow, concurrency.
# The ASan build runs `unit`; the TSan build runs `concurrency`.
function(crease_test name)
  cmake_parse_arguments(T "" "TIMEOUT" "SOURCES;LIBS;LABELS;DEPENDS" ${ARGN})
  string(REPLACE "." "_" exe "test_${name}")
  add_executable(${exe} ${T_SOURCES})
  target_link_libraries(${exe} PRIVATE crease_test_main crease_rt_alloc_hooks crease_options ${T_LIBS})
  set_target_properties(${exe} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests ENABLE_EXPORTS ON)
  target_compile_definitions(${exe} PRIVATE
    CREASE_PLUGIN_DIR="${CREASE_PLUGIN_DIR}" CREASE_SOURCE_DIR="${CMAKE_SOURCE_DIR}"
    CREASE_BIN_DIR="${CREASE_BIN_DIR}")
  if(T_DEPENDS)
    add_dependencies(${exe} ${T_DEPENDS})
  endif()
  add_test(NAME ${name} COMMAND ${exe})
  if(NOT T_LABELS)
    set(T_LABELS unit)
  endif()
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  set_tests_properties(${name} PROPERTIES LABELS "${T_LABELS}" TIMEOUT ${T_TIMEOUT})
  foreach(label ${T_LABELS})
    set_property(GLOBAL APPEND PROPERTY CREASE_TESTS_${label} ${exe})
  endforeach()
endfunction()

# Targets `tests-unit`, `tests-concurrency`, ... build just the executables of one label,
# so the sanitizer builds compile only what they run. `crease_all_plugins` builds every plugin.
# crease_compile_fail_test(NAME SOURCE file EXPECT regex)
# A file that must not compile (a static_assert's test): passes when the compiler's output
# matches EXPECT. Label unit; nothing to build.
function(crease_compile_fail_test name)
  cmake_parse_arguments(T "" "SOURCE;EXPECT" "" ${ARGN})
  add_test(NAME ${name} COMMAND ${CMAKE_CXX_COMPILER} -std=c++20 -fsyntax-only -I${CMAKE_SOURCE_DIR}
           ${CMAKE_CURRENT_SOURCE_DIR}/${T_SOURCE})
  set_tests_properties(${name} PROPERTIES LABELS unit PASS_REGULAR_EXPRESSION "${T_EXPECT}")
endfunction()

function(crease_finish_test_targets)
  get_property(plugins GLOBAL PROPERTY CREASE_ALL_PLUGINS)
  add_custom_target(crease_all_plugins)
  if(plugins)
    add_dependencies(crease_all_plugins ${plugins})
  endif()
  foreach(label unit hil slow concurrency)
    get_property(exes GLOBAL PROPERTY CREASE_TESTS_${label})
    add_custom_target(tests-${label})
    if(exes)
      add_dependencies(tests-${label} ${exes})
    endif()
  endforeach()
endfunction()

# Adds every immediate subfolder of the current folder that has a CMakeLists.txt.
function(crease_add_subdirs)
  file(GLOB dirs LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR}/*)
  list(SORT dirs)
  foreach(dir ${dirs})
    if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${dir} AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${dir}/CMakeLists.txt)
      add_subdirectory(${dir})
    endif()
  endforeach()
endfunction()
