# Read by cpack in a cross build (CPACK_PROJECT_CONFIG_FILE, cmake/SemapPackaging.cmake): the
# package's Depends, which scripts/package --arm64 computed with dpkg-shlibdeps from the target's
# libraries in the sysroot and the shlibs / symbols files of the arm64 packages they came from.
if(NOT EXISTS "${CPACK_SEMAP_DEPENDS_FILE}")
  message(FATAL_ERROR "${CPACK_SEMAP_DEPENDS_FILE} is missing: build a cross package with "
                      "scripts/package --arm64, which computes its dependencies first")
endif()
file(READ "${CPACK_SEMAP_DEPENDS_FILE}" CPACK_DEBIAN_PACKAGE_DEPENDS)
string(STRIP "${CPACK_DEBIAN_PACKAGE_DEPENDS}" CPACK_DEBIAN_PACKAGE_DEPENDS)
