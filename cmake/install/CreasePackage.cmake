# The Debian package: `cpack --config build/release/CPackConfig.cmake -G DEB` builds
# crease_<version>_amd64.deb from the install rules (cmake/CreaseInstall.cmake).
# Run-time dependencies come from the binaries themselves (dpkg-shlibdeps), so the package
# needs the libraries creased and the plugins link, not the -dev packages that build them.
set(CPACK_PACKAGE_NAME crease)
set(CPACK_PACKAGE_VENDOR "Crease")
set(CPACK_PACKAGE_CONTACT "Crease maintainers <crease@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Real-time plugin framework for a paper-folding robot")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX /opt/crease)
set(CPACK_INSTALL_PREFIX /opt/crease)  # with CPACK_SET_DESTDIR, the prefix cpack installs under
# Absolute destinations (/etc/crease, /lib/systemd/system) land in the package, not on the host.
set(CPACK_SET_DESTDIR ON)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS
    ${CMAKE_BINARY_DIR}/rt ${CMAKE_BINARY_DIR}/core ${CMAKE_BINARY_DIR}/core/frames)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "adduser")

# Conffiles: every file under /etc/crease (dpkg keeps a lab's edits on upgrade).
set(conffiles "${CREASE_INSTALL_CONFDIR}/robot.yaml\n")
foreach(sub ${CREASE_ETC_SUBDIRS})
  file(GLOB_RECURSE files RELATIVE ${CMAKE_SOURCE_DIR}/config ${CMAKE_SOURCE_DIR}/config/${sub}/*)
  foreach(f ${files})
    string(APPEND conffiles "${CREASE_INSTALL_CONFDIR}/${f}\n")
  endforeach()
endforeach()
file(WRITE ${CMAKE_BINARY_DIR}/debian/conffiles "${conffiles}")
configure_file(${CMAKE_SOURCE_DIR}/cmake/install/postinst ${CMAKE_BINARY_DIR}/debian/postinst COPYONLY)
configure_file(${CMAKE_SOURCE_DIR}/cmake/install/postrm ${CMAKE_BINARY_DIR}/debian/postrm COPYONLY)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${CMAKE_BINARY_DIR}/debian/conffiles ${CMAKE_BINARY_DIR}/debian/postinst ${CMAKE_BINARY_DIR}/debian/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)

include(CPack)
