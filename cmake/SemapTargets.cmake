# Helpers that give every project target the same warnings, layout and labels.

set(SEMAP_WARNINGS -Wall -Wextra -Wpedantic -Werror)

# The numeric libraries (estimation, mapping) may be compiled for a newer x86-64 level than
# the rest, e.g. x86-64-v3 (AVX2 + FMA) on the robot computer that builds them. Eigen's object
# layout must not depend on that, so alignment is capped at 16 bytes for every target: AVX code
# then uses unaligned 32-byte loads, which cost nothing extra on CPUs that have AVX2.
set(SEMAP_SIMD_ARCH "" CACHE STRING
    "-march for estimation and mapping (e.g. x86-64-v3); empty keeps the compiler default")
add_compile_definitions(EIGEN_MAX_ALIGN_BYTES=16)
if(SEMAP_SIMD_ARCH)
  # Only when this machine can run it: a binary built here for a level the CPU lacks would
  # die with SIGILL in the tests.
  include(CheckCXXSourceRuns)
  set(CMAKE_REQUIRED_FLAGS "-march=${SEMAP_SIMD_ARCH}")
  check_cxx_source_runs([[
    int main() {
      __builtin_cpu_init();
    #ifdef __AVX2__
      if (!__builtin_cpu_supports("avx2")) return 1;
    #endif
    #ifdef __FMA__
      if (!__builtin_cpu_supports("fma")) return 1;
    #endif
    #ifdef __AVX512F__
      if (!__builtin_cpu_supports("avx512f")) return 1;
    #endif
      return 0;
    }]] SEMAP_SIMD_ARCH_RUNS_${SEMAP_SIMD_ARCH})
  unset(CMAKE_REQUIRED_FLAGS)
  if(NOT SEMAP_SIMD_ARCH_RUNS_${SEMAP_SIMD_ARCH})
    message(WARNING "SEMAP_SIMD_ARCH=${SEMAP_SIMD_ARCH} does not run on this CPU: building portable code")
    set(SEMAP_SIMD_ARCH "")
  endif()
endif()

# semap_simd_tuned(TARGET [CONTRACT_FMA]): compiles TARGET's own sources for SEMAP_SIMD_ARCH.
# Without CONTRACT_FMA no automatic FMA contraction: results stay bit-identical to the untuned
# code that tests compare against (Eigen still uses FMA explicitly in its vector kernels).
# CONTRACT_FMA lets the compiler fuse a * b + c where the target's tests compare with
# tolerances, not bits.
function(semap_simd_tuned target)
  cmake_parse_arguments(arg "CONTRACT_FMA" "" "" ${ARGN})
  if(SEMAP_SIMD_ARCH)
    set(contract off)
    if(arg_CONTRACT_FMA)
      set(contract fast)
    endif()
    target_compile_options(${target} PRIVATE -march=${SEMAP_SIMD_ARCH} -ffp-contract=${contract})
  endif()
endfunction()

# Every library folder, in dependency order: later folders may link earlier ones, never the
# reverse. map_io (file formats, exports, offline evaluation) sits on top of mapping and is
# linked by the offline tools only, never by semap-onboard.
set(SEMAP_LIBRARIES common firmware_bridge drivers estimation perception mapping map_io dds_idl onboard sim)
# Library folders that a narrow SEMAP_ONLY list must not include without another one.
set(semap_map_io_needs mapping perception)
set(semap_onboard_needs drivers estimation perception mapping dds_idl)
set(semap_sim_needs firmware_bridge estimation perception)
# Links a library must never make, though the order above would allow them: the robot's
# pipeline runs without file-format tools and without the simulator.
set(semap_onboard_forbids map_io sim sim_rig)
foreach(lib IN LISTS SEMAP_LIBRARIES)
  if(SEMAP_ONLY STREQUAL "" OR lib IN_LIST SEMAP_ONLY)
    set(semap_wants_${lib} TRUE)
  else()
    set(semap_wants_${lib} FALSE)
  endif()
endforeach()
foreach(lib IN LISTS SEMAP_LIBRARIES)
  foreach(dep IN LISTS semap_${lib}_needs)
    if(semap_wants_${lib} AND NOT semap_wants_${dep})
      message(FATAL_ERROR "SEMAP_ONLY lists ${lib} without ${dep}, which it links")
    endif()
  endforeach()
endforeach()

# Tests that start other programs of this build (the *_cli_tests, the mapping tools, the dds and
# e2e suites, the HIL tool tests) need the host to exec them. In the arm64 cross build
# (scripts/cross-arm64) ctest runs each test binary under qemu-user, but the test's own execv of an
# aarch64 program fails on the x86-64 kernel ("Exec format error": qemu is not registered with
# binfmt_misc), so those tests are not built there. tests/e2e/arm64_robot_test.sh runs the arm64
# semap-onboard under qemu-user instead.
if(CMAKE_CROSSCOMPILING)
  set(SEMAP_TESTS_RUN_PROGRAMS FALSE)
else()
  set(SEMAP_TESTS_RUN_PROGRAMS TRUE)
endif()

# semap_fuzz_instrumented(TARGET): with SEMAP_FUZZ, compiles TARGET's sources with libFuzzer's
# coverage hooks, ASan and UBSan (stopping at the first undefined behaviour). Every library a fuzz
# target reaches needs this: without it libFuzzer sees no coverage inside the parser and ASan no
# out-of-bounds access there. The fuzzer runtime itself is linked by the fuzz target only.
function(semap_fuzz_instrumented target)
  if(SEMAP_FUZZ)
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link,address,undefined
                           -fno-sanitize-recover=undefined)
  endif()
endfunction()

# semap_library(NAME SOURCES ... [PUBLIC_LIBS ...] [PRIVATE_LIBS ...])
# Creates semap_<NAME> (alias semap::<NAME>) with include/ as its public header root.
function(semap_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_LIBS;PRIVATE_LIBS" ${ARGN})
  add_library(semap_${name} ${ARG_SOURCES})
  add_library(semap::${name} ALIAS semap_${name})
  target_include_directories(semap_${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_compile_options(semap_${name} PRIVATE ${SEMAP_WARNINGS})
  target_link_libraries(semap_${name} PUBLIC ${ARG_PUBLIC_LIBS} PRIVATE ${ARG_PRIVATE_LIBS})
  semap_fuzz_instrumented(semap_${name})
endfunction()

# semap_executable(NAME SOURCES ... LIBS ...): an app in build/bin.
function(semap_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_compile_options(${name} PRIVATE ${SEMAP_WARNINGS})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS})
  # The user-facing tools (semap-*) are installed; bench helpers stay in the build tree.
  if(name MATCHES "^semap-")
    install(TARGETS ${name} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endfunction()

# semap_test(NAME SOURCES ... LIBS ... [LABELS ...] [TIMEOUT s] [ENV ...])
# A GoogleTest binary registered as one ctest test per binary (keeps ctest output short).
function(semap_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;LIBS;LABELS;ENV" ${ARGN})
  find_package(GTest REQUIRED)
  add_executable(${name} ${ARG_SOURCES})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  target_compile_options(${name} PRIVATE ${SEMAP_WARNINGS})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gmock GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE
    SEMAP_SHARED_DATA_DIR="${PROJECT_SOURCE_DIR}/../shared/data"
    SEMAP_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  add_test(NAME ${name} COMMAND ${name})
  set_tests_properties(${name} PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT})
  if(ARG_ENV)
    set_tests_properties(${name} PROPERTIES ENVIRONMENT "${ARG_ENV}")
  endif()
  semap_sanitizer_suite(${name} ${name})
endfunction()

# semap_sanitizer_suite(TEST TARGETS...): when TEST is in SEMAP_SANITIZER_SUITE (tests/), labels it
# `sanitize` and makes the target `sanitizer_suite` build TARGETS, so the sanitizer presets build
# and run that suite alone.
function(semap_sanitizer_suite test)
  if(TARGET sanitizer_suite AND test IN_LIST SEMAP_SANITIZER_SUITE)
    set_property(TEST ${test} APPEND PROPERTY LABELS sanitize)
    add_dependencies(sanitizer_suite ${ARGN})
  endif()
endfunction()

# semap_bench(NAME SOURCES ... LIBS ...): a Google Benchmark binary in build/bin.
function(semap_bench name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  find_package(benchmark REQUIRED)
  add_executable(${name} ${ARG_SOURCES})
  target_compile_options(${name} PRIVATE ${SEMAP_WARNINGS})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} benchmark::benchmark)
endfunction()

# semap_fuzz(NAME SOURCES ... LIBS ... [CORPUS dir])
# With SEMAP_FUZZ (clang preset `fuzz`) a libFuzzer binary; otherwise the same entry point
# linked with a replay main that runs the seed corpus, so every build exercises the target.
function(semap_fuzz name)
  cmake_parse_arguments(ARG "" "CORPUS" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/fuzz)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/fuzz)
  target_compile_options(${name} PRIVATE ${SEMAP_WARNINGS})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS})
  if(SEMAP_FUZZ)
    # Undefined behaviour stops the run like a crash (recovering would only log it).
    target_compile_options(${name} PRIVATE -fsanitize=fuzzer,address,undefined
                           -fno-sanitize-recover=undefined)
    target_link_options(${name} PRIVATE -fsanitize=fuzzer,address,undefined)
  else()
    target_sources(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/fuzz/replay_main.cpp)
    if(ARG_CORPUS)
      add_test(NAME ${name}_replay COMMAND ${name} ${ARG_CORPUS})
      set_tests_properties(${name}_replay PROPERTIES LABELS "fuzz;unit" TIMEOUT 120)
    endif()
  endif()
endfunction()

# Adds every immediate subfolder of DIR that has a CMakeLists.txt, so each area owns its own.
function(semap_add_subfolders dir)
  file(GLOB children RELATIVE ${CMAKE_CURRENT_SOURCE_DIR}/${dir}
       CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${dir}/*/CMakeLists.txt)
  list(SORT children)
  foreach(child IN LISTS children)
    get_filename_component(sub ${child} DIRECTORY)
    # Area folders named after a library (`mapping`, `mapping_tools`) are skipped when that
    # library is not built.
    set(skip FALSE)
    foreach(lib IN LISTS SEMAP_LIBRARIES)
      if((sub STREQUAL lib OR sub MATCHES "^${lib}_") AND NOT semap_wants_${lib})
        set(skip TRUE)
      endif()
    endforeach()
    if(NOT skip)
      add_subdirectory(${dir}/${sub})
    endif()
  endforeach()
endfunction()

# semap_check_layering(): every semap library links only libraries of earlier folders and none
# its folder forbids, directly or through another library; a wrong link stops the configure
# step, and since headers come only with a link, a wrong include then fails the build.
function(semap_check_layering)
  set(position 0)
  foreach(lib IN LISTS SEMAP_LIBRARIES)
    set(rank_${lib} ${position})
    math(EXPR position "${position} + 1")
  endforeach()
  set(rank_sim_rig ${rank_sim})
  foreach(lib IN LISTS SEMAP_LIBRARIES ITEMS sim_rig)
    if(NOT TARGET semap_${lib})
      continue()
    endif()
    set(todo semap_${lib})
    set(seen "")
    while(todo)
      list(POP_FRONT todo target)
      get_target_property(links ${target} LINK_LIBRARIES)
      foreach(link IN LISTS links)
        if(TARGET ${link})
          get_target_property(aliased ${link} ALIASED_TARGET)
          if(aliased)
            set(link ${aliased})
          endif()
        endif()
        if(NOT link MATCHES "^semap_(.+)$" OR link IN_LIST seen)
          continue()
        endif()
        set(dep ${CMAKE_MATCH_1})
        list(APPEND seen ${link})
        list(APPEND todo ${link})
        if(dep IN_LIST semap_${lib}_forbids)
          message(FATAL_ERROR "semap_${lib} must not link semap_${dep} (semap_${lib}_forbids)")
        endif()
        if(DEFINED rank_${dep} AND rank_${dep} GREATER rank_${lib})
          message(FATAL_ERROR "semap_${lib} links semap_${dep}, a later folder")
        endif()
      endforeach()
    endwhile()
  endforeach()
endfunction()
