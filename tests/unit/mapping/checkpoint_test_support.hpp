#pragma once

// What the checkpoint tests share: scratch directories (also across a death test's re-executed
// child) and bit-for-bit map comparison.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "semap/mapping/semantic_map.hpp"

namespace semap::mapping::testing {

inline std::filesystem::path scratch_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("semap_checkpoint_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::create_directories(dir);
  return dir;
}

// The directory a death test shares with its child (the same binary, re-executed, which
// inherits the environment), removed with the variable at the end of the test.
class SharedDir {
 public:
  explicit SharedDir(const std::string& name) {
    const char* inherited = std::getenv(kVariable);
    dir_ = inherited != nullptr ? std::filesystem::path(inherited) : scratch_dir(name);
    ::setenv(kVariable, dir_.c_str(), 1);
  }
  ~SharedDir() {
    ::unsetenv(kVariable);
    std::filesystem::remove_all(dir_);
  }
  SharedDir(const SharedDir&) = delete;
  SharedDir& operator=(const SharedDir&) = delete;
  const std::filesystem::path& path() const { return dir_; }

 private:
  static constexpr const char* kVariable = "SEMAP_CHECKPOINT_TEST_DIR";
  std::filesystem::path dir_;
};

// Bit-for-bit equality of the blocks in memory.
inline void expect_same_map(const SemanticMap& a, const SemanticMap& b) {
  EXPECT_EQ(a.stats().blocks, b.stats().blocks);
  std::size_t differing = 0;
  a.for_each_block([&](const common::BlockIndex& index, const Block& block) {
    const Block* other = b.find_block(index);
    if (other == nullptr || block.dense() != other->dense() ||
        !std::equal(block.observed_words().begin(), block.observed_words().end(),
                    other->observed_words().begin())) {
      ++differing;
    }
  });
  EXPECT_EQ(differing, 0u);
}

}  // namespace semap::mapping::testing
