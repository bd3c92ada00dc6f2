# `cmake --install` and the Debian package (scripts/package, CPack DEB). Layout:
#   /usr/bin/semap-*                          the executables
#   /usr/share/semap/{config,models}/, imu.dbc the examples, the shipped models (cards, networks,
#                                             licences), the IMU's DBC
#   /usr/share/doc/semap/                     README and docs
#   /etc/semap/semap.yaml, cyclonedds.xml     the robot's configuration (conffiles)
#   /lib/systemd/system/semap-onboard.service the service (docs/deploy.md)
# Configs name data relative to the working directory; the service runs in /usr/share/semap,
# so models/ and config/ resolve there, never in a source tree.
include(GNUInstallDirs)

set(SEMAP_DATA_DIR ${CMAKE_INSTALL_DATADIR}/semap)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/ DESTINATION ${SEMAP_DATA_DIR}/config
        PATTERN "*.service" EXCLUDE)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/models/ DESTINATION ${SEMAP_DATA_DIR}/models
        FILES_MATCHING PATTERN "*.onnx" PATTERN "*.net" PATTERN "*.yaml" PATTERN "*.LICENSE")
install(FILES ${PROJECT_SOURCE_DIR}/firmware_bridge/imu.dbc DESTINATION ${SEMAP_DATA_DIR})
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR})
# With the /usr prefix GNUInstallDirs puts sysconf in /etc (install with DESTDIR to stage).
install(FILES ${PROJECT_SOURCE_DIR}/config/robot-rgbd.yaml DESTINATION
        ${CMAKE_INSTALL_FULL_SYSCONFDIR}/semap RENAME semap.yaml)
install(FILES ${PROJECT_SOURCE_DIR}/config/cyclonedds-loopback.xml DESTINATION
        ${CMAKE_INSTALL_FULL_SYSCONFDIR}/semap RENAME cyclonedds.xml)
install(FILES ${PROJECT_SOURCE_DIR}/config/semap-onboard.service DESTINATION lib/systemd/system)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME semap)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "semap developers <semap@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Onboard semantic mapping for robots: drivers, InEKF, S-BKI map, DDS")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # semap_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
if(CMAKE_CROSSCOMPILING)
  # A cross build (scripts/cross-arm64): the package is for the target's architecture, and
  # dpkg-shlibdeps, run by CPack, would look the libraries up among the build machine's installed
  # packages. scripts/package --arm64 runs it against the sysroot's arm64 packages instead and
  # writes the Depends line to deb/depends, which cmake/SemapCPackCross.cmake reads at cpack time
  # (a plain `cpack` before that fails rather than pack a package without dependencies).
  if(CMAKE_SYSTEM_PROCESSOR STREQUAL "aarch64")
    set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE arm64)
  else()
    message(FATAL_ERROR "SemapPackaging: no Debian architecture for ${CMAKE_SYSTEM_PROCESSOR}")
  endif()
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS OFF)
  set(CPACK_SEMAP_DEPENDS_FILE ${CMAKE_BINARY_DIR}/deb/depends)
  set(CPACK_PROJECT_CONFIG_FILE ${PROJECT_SOURCE_DIR}/cmake/SemapCPackCross.cmake)
endif()
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "can-utils")
# dpkg keeps an edited /etc/semap file across upgrades.
file(WRITE ${CMAKE_BINARY_DIR}/deb/conffiles "/etc/semap/semap.yaml\n/etc/semap/cyclonedds.xml\n")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${CMAKE_BINARY_DIR}/deb/conffiles)
include(CPack)
