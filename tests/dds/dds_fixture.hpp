#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "child_process.hpp"

namespace semap::dds_idl::testing {

// One random domain per test binary run, so parallel runs on the machine never see each
// other; each test uses its own topic namespace on top.
inline int test_domain() {
  static const int domain = [] {
    std::random_device rd;
    return 1 + static_cast<int>(rd() % 200);
  }();
  return domain;
}

class DdsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // ctest sets CYCLONEDDS_URI; refuse to touch a real network without it.
    const char* uri = std::getenv("CYCLONEDDS_URI");
    ASSERT_NE(uri, nullptr) << "CYCLONEDDS_URI must point at config/cyclonedds-loopback.xml";
  }

  // A namespace unique to this test and process.
  static std::string unique_ns(const std::string& stem) {
    return stem + "_" + std::to_string(getpid());
  }

  static std::vector<std::string> peer(const std::string& role, std::vector<std::string> args) {
    std::vector<std::string> argv{SEMAP_DDS_PEER, role, "--domain", std::to_string(test_domain())};
    argv.insert(argv.end(), args.begin(), args.end());
    return argv;
  }
};

using std::chrono::milliseconds;
using std::chrono::seconds;

}  // namespace semap::dds_idl::testing
