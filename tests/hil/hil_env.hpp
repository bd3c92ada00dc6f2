#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <functional>
#include <string>
#include <thread>

namespace semap::hil {

// scripts/hil-qemu sets SEMAP_HIL_REQUIRE=1 inside its VM: there a missing vcan0 or vivid is a
// broken image and must fail. On a host without them the test is reported as skipped.
inline bool hil_required() {
  const char* v = std::getenv("SEMAP_HIL_REQUIRE");
  return v != nullptr && std::string(v) == "1";
}

// Polls `done` until it holds or `timeout` passes; returns its last value.
inline bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return done();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

}  // namespace semap::hil

// Skips (host without the device) or fails (inside the HIL VM) the current test.
#define SEMAP_HIL_UNAVAILABLE(why)                                             \
  do {                                                                         \
    if (::semap::hil::hil_required()) FAIL() << "HIL device missing: " << why; \
    GTEST_SKIP() << why;                                                       \
  } while (0)
