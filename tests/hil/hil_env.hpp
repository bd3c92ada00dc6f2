#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
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

// A program given to scripts/hil-qemu (--payload) sits next to the test binary; natively it is
// where the build put it (`built`). "" when neither exists.
inline std::string find_program(const std::string& name, const std::string& built) {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec && std::filesystem::exists(self.parent_path() / name)) {
    return (self.parent_path() / name).string();
  }
  return std::filesystem::exists(built) ? built : "";
}

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace semap::hil

// Skips (host without the device) or fails (inside the HIL VM) the current test.
#define SEMAP_HIL_UNAVAILABLE(why)                                             \
  do {                                                                         \
    if (::semap::hil::hil_required()) FAIL() << "HIL device missing: " << why; \
    GTEST_SKIP() << why;                                                       \
  } while (0)
