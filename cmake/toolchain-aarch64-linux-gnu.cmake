# Cross-compiles for arm64 (aarch64) with Debian's cross toolchain (g++-aarch64-linux-gnu) against
# a sysroot of arm64 -dev packages extracted with dpkg-deb (scripts/cross-arm64 builds it):
#
#   cmake -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-aarch64-linux-gnu.cmake -DSEMAP_SYSROOT=DIR ...
#
# libc, libstdc++ and libgcc come from the toolchain (/usr/aarch64-linux-gnu), everything else
# from SEMAP_SYSROOT. Test binaries run under qemu-user (CMAKE_CROSSCOMPILING_EMULATOR), so
# `ctest` works unchanged: the tests are emulated, not run on arm64 hardware.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

set(SEMAP_SYSROOT "" CACHE PATH "Root of the extracted arm64 -dev packages")
set(SEMAP_TOOLCHAIN_ROOT /usr/aarch64-linux-gnu CACHE PATH "The cross toolchain's target libc")
# try_compile projects see only the variables listed here.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES SEMAP_SYSROOT SEMAP_TOOLCHAIN_ROOT)
if(NOT SEMAP_SYSROOT)
  message(FATAL_ERROR "toolchain-aarch64-linux-gnu: set -DSEMAP_SYSROOT (scripts/cross-arm64)")
endif()

set(CMAKE_FIND_ROOT_PATH ${SEMAP_SYSROOT} ${SEMAP_TOOLCHAIN_ROOT})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# Some arm64 packages install their libraries in /usr/lib (GDAL's armadillo, HDF4, OGDI).
set(semap_arm64_libdirs
    ${SEMAP_SYSROOT}/usr/lib/aarch64-linux-gnu ${SEMAP_SYSROOT}/lib/aarch64-linux-gnu
    ${SEMAP_SYSROOT}/usr/lib)
# No --sysroot (libc is not in it): the packages' CMake configs point their targets at the
# sysroot's headers and libraries.
# Shared libraries pull in others (spdlog -> fmt): let the linker find those in the sysroot.
string(REPLACE ";" ":" semap_arm64_libpath "${semap_arm64_libdirs}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-Wl,-rpath-link,${semap_arm64_libpath}")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-Wl,-rpath-link,${semap_arm64_libpath}")

# Debian keeps architecture-dependent headers in /usr/include/<triplet> (Cyclone DDS's
# dds/features.h), a default include folder of the native compiler; the cross compiler searches
# only its own, so the sysroot's is added to every compile.
set(CMAKE_C_FLAGS_INIT "-isystem ${SEMAP_SYSROOT}/usr/include/${CMAKE_LIBRARY_ARCHITECTURE}")
set(CMAKE_CXX_FLAGS_INIT "-isystem ${SEMAP_SYSROOT}/usr/include/${CMAKE_LIBRARY_ARCHITECTURE}")

set(ENV{PKG_CONFIG_SYSROOT_DIR} ${SEMAP_SYSROOT})
set(ENV{PKG_CONFIG_LIBDIR}
    "${SEMAP_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${SEMAP_SYSROOT}/usr/share/pkgconfig")

# ctest runs each test binary as `qemu-aarch64 -L <libc root> -E LD_LIBRARY_PATH=<sysroot libs>
# <test>`; -E sets the variable for the emulated program only, not for qemu itself.
find_program(SEMAP_QEMU_AARCH64 qemu-aarch64 REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR
    ${SEMAP_QEMU_AARCH64} -L ${SEMAP_TOOLCHAIN_ROOT} -E LD_LIBRARY_PATH=${semap_arm64_libpath})
