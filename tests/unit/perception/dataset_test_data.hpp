#pragma once

// Where the dataset reader tests find real recordings (../shared/data/real, next to the
// checkout). A test skips when its folder is absent:
//   if (!std::filesystem::exists(dir)) GTEST_SKIP() << absent(dir);

#include <filesystem>
#include <string>

namespace semap::perception::testing {

inline std::filesystem::path real_data(const std::string& folder) {
  return std::filesystem::path(SEMAP_SHARED_DATA_DIR) / "real" / folder;
}

inline std::string absent(const std::filesystem::path& path) {
  return path.string() + " is absent (real recordings: ../shared/data/real, see its README.md)";
}

}  // namespace semap::perception::testing
