# Install rules, the plugin SDK and the Debian package (CPack). Included once, at the end of the
# top-level CMakeLists.txt, when every target exists.
#
#   cmake --install build/release [--prefix /opt/crease]      # the tree below, under the prefix
#   cpack --config build/release/CPackConfig.cmake -G DEB      # crease_<version>_amd64.deb
#
# <prefix>/bin                 creased and the tools
# <prefix>/lib                 the shared libraries creased and the plugins link (libcrease_*.so)
# <prefix>/lib/crease/plugins  the plugins: the one directory the installed configurations allow
# <prefix>/share/crease/config the example configurations, calibrations, marker layouts, URDF
# <prefix>/include/crease      the plugin SDK's headers; <prefix>/lib/cmake/Crease its package
# /etc/crease                  the robot's configuration (Debian conffiles), plugin_dirs absolute
# /lib/systemd/system          creased.service (installed, not enabled)
# Directories are 0755 and files 0644 / 0755 whatever the umask: the daemon refuses plugins in
# a place writable by group or others.
include(CMakePackageConfigHelpers)

set(CREASE_INSTALL_CONFDIR /etc/crease CACHE PATH "where the robot's configuration is installed")
set(CREASE_INSTALL_UNITDIR /lib/systemd/system CACHE PATH "where creased.service is installed")
set(CREASE_INSTALL_DATADIR share/crease)
set(CREASE_INSTALL_CMAKEDIR lib/cmake/Crease)
set(CMAKE_INSTALL_DEFAULT_DIRECTORY_PERMISSIONS
    OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)

# The SDK's major version is the plugin ABI's (core/abi.h): find_package(Crease 2) finds an SDK
# of ABI 2 only, and plugins built against it load into a daemon of that ABI.
file(STRINGS ${CMAKE_SOURCE_DIR}/core/abi.h abi_line REGEX "^#define CREASE_PLUGIN_ABI_VERSION")
string(REGEX REPLACE ".* ([0-9]+)u?$" "\\1" CREASE_ABI_VERSION "${abi_line}")
set(CREASE_SDK_VERSION ${CREASE_ABI_VERSION}.${PROJECT_VERSION_MINOR}.${PROJECT_VERSION_PATCH})

# --- programs and shared libraries
install(TARGETS creased creasectl crease-markers crease-calibrate crease-simdevice crease-fold-graph
        RUNTIME DESTINATION bin COMPONENT runtime)
set_target_properties(crease_rt PROPERTIES EXPORT_NAME rt)
set_target_properties(crease_frames PROPERTIES EXPORT_NAME frames)
set_target_properties(crease_core PROPERTIES EXPORT_NAME core)   # Crease::core, what a plugin links
install(TARGETS crease_rt crease_frames crease_core EXPORT CreaseTargets
        LIBRARY DESTINATION lib COMPONENT runtime
        INCLUDES DESTINATION ${CREASE_INSTALL_INCLUDEDIR})
# (plugins: crease_plugin() in CreaseTargets.cmake installs each into lib/crease/plugins)

# --- configurations. The installed copies name the installed plugin directory instead of the
# build tree's and write no report unless asked (--report-dir): the installed tree is read-only.
set(installed_config ${CMAKE_BINARY_DIR}/installed-config)
# config/*.yaml and the split's config/split/*.yaml (one folder deeper: one more ../).
file(GLOB config_yamls RELATIVE ${CMAKE_SOURCE_DIR}/config ${CMAKE_SOURCE_DIR}/config/*.yaml
     ${CMAKE_SOURCE_DIR}/config/split/*.yaml)
foreach(y ${config_yamls})
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/config/${y})
  file(READ ${CMAKE_SOURCE_DIR}/config/${y} text)
  string(REGEX REPLACE "plugin_dirs: \\[[^]\n]*\\]" "plugin_dirs: [@CREASE_PLUGIN_DIRS@]" text "${text}")
  string(REGEX REPLACE "\n  report_dir: [^\n]*" "" text "${text}")
  file(WRITE ${installed_config}/${y}.in "${text}")
endforeach()
install(DIRECTORY ${CMAKE_SOURCE_DIR}/config/ DESTINATION ${CREASE_INSTALL_DATADIR}/config COMPONENT runtime
        FILE_PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ
        PATTERN "creased.service" EXCLUDE REGEX "/config/(split/)?[^/]*\\.yaml$" EXCLUDE)
# The robot's own configuration goes to /etc/crease with what it reads (cameras, markers, robot).
set(CREASE_ETC_SUBDIRS cameras markers robot dds)  # what robot.yaml reads; conffiles too
foreach(sub ${CREASE_ETC_SUBDIRS})
  install(DIRECTORY ${CMAKE_SOURCE_DIR}/config/${sub} DESTINATION ${CREASE_INSTALL_CONFDIR} COMPONENT runtime
          FILE_PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
endforeach()
# Written at install time, when the prefix is known (cmake --install --prefix ...), then
# installed like every file (DESTDIR honoured, modes fixed, listed in install_manifest.txt).
install(CODE "
  set(CMAKE_INSTALL_DEFAULT_DIRECTORY_PERMISSIONS ${CMAKE_INSTALL_DEFAULT_DIRECTORY_PERMISSIONS})
  set(out \"${installed_config}/out\")
  set(modes FILE_PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
  file(REMOVE_RECURSE \"\${out}\")
  foreach(y ${config_yamls})
    file(READ \"${installed_config}/\${y}.in\" text)
    set(up \"../../../\")
    if(y MATCHES \"/\")
      set(up \"../../../../\")
    endif()
    string(REPLACE \"@CREASE_PLUGIN_DIRS@\" \"\${up}${CREASE_INSTALL_PLUGINDIR}\" text \"\${text}\")
    file(WRITE \"\${out}/share/\${y}\" \"\${text}\")
  endforeach()
  file(INSTALL \${out}/share/ DESTINATION \"\${CMAKE_INSTALL_PREFIX}/${CREASE_INSTALL_DATADIR}/config\" \${modes})
  file(READ \"${installed_config}/robot.yaml.in\" text)
  string(REPLACE \"@CREASE_PLUGIN_DIRS@\" \"\${CMAKE_INSTALL_PREFIX}/${CREASE_INSTALL_PLUGINDIR}\" text \"\${text}\")
  file(WRITE \"\${out}/etc/robot.yaml\" \"\${text}\")
  file(INSTALL \${out}/etc/robot.yaml DESTINATION \"${CREASE_INSTALL_CONFDIR}\" \${modes})
  file(READ \"${CMAKE_SOURCE_DIR}/config/creased.service\" unit)
  string(REPLACE \"/opt/crease/bin\" \"\${CMAKE_INSTALL_PREFIX}/bin\" unit \"\${unit}\")
  string(REPLACE \"/opt/crease/README.md\" \"\${CMAKE_INSTALL_PREFIX}/share/doc/crease/README.md\" unit \"\${unit}\")
  string(REPLACE \"/etc/crease\" \"${CREASE_INSTALL_CONFDIR}\" unit \"\${unit}\")
  file(WRITE \"\${out}/unit/creased.service\" \"\${unit}\")
  file(INSTALL \${out}/unit/creased.service DESTINATION \"${CREASE_INSTALL_UNITDIR}\" \${modes})
" COMPONENT runtime)
install(FILES ${CMAKE_SOURCE_DIR}/README.md DESTINATION share/doc/crease COMPONENT runtime)

# --- the plugin SDK: the plugin contract's headers only (what core/plugin.h includes, the port
# payload types), the exported core libraries, crease_plugin() with the in-tree flags.
set(sdk_headers
  core/abi.h core/assert.h core/errors.h core/params.h core/plugin.h core/port.h core/port_binder.h
  core/port_registry.h core/status.h core/frames/frame_channel.h
  rt/clock.h rt/latest.h rt/log_queue.h rt/queue.h)
foreach(h ${sdk_headers})
  get_filename_component(dir ${h} DIRECTORY)
  install(FILES ${CMAKE_SOURCE_DIR}/${h} DESTINATION ${CREASE_INSTALL_INCLUDEDIR}/${dir} COMPONENT sdk)
endforeach()
install(DIRECTORY ${CMAKE_SOURCE_DIR}/core/port_types DESTINATION ${CREASE_INSTALL_INCLUDEDIR}/core
        COMPONENT sdk FILES_MATCHING PATTERN "*.h")
install(EXPORT CreaseTargets NAMESPACE Crease:: DESTINATION ${CREASE_INSTALL_CMAKEDIR} COMPONENT sdk)
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/install/CreaseConfig.cmake.in
  ${CMAKE_BINARY_DIR}/CreaseConfig.cmake INSTALL_DESTINATION ${CREASE_INSTALL_CMAKEDIR})
write_basic_package_version_file(${CMAKE_BINARY_DIR}/CreaseConfigVersion.cmake
  VERSION ${CREASE_SDK_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_BINARY_DIR}/CreaseConfig.cmake ${CMAKE_BINARY_DIR}/CreaseConfigVersion.cmake
              ${CMAKE_SOURCE_DIR}/cmake/CreasePluginFlags.cmake
        DESTINATION ${CREASE_INSTALL_CMAKEDIR} COMPONENT sdk)

# --- the Debian package
include(${CMAKE_SOURCE_DIR}/cmake/install/CreasePackage.cmake)
