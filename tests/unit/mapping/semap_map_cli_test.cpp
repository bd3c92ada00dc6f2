// Runs build/bin/semap-map as a user would and checks its output files and exit codes.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "semap/map_io/pcd_io.hpp"
#include "support/cli_run.hpp"

namespace semap::mapping {
namespace {

namespace fs = std::filesystem;

using test_support::CliResult;

CliResult run(const std::string& args) { return test_support::run_cli(SEMAP_MAP_EXE, args); }

std::string toy(int i) {
  return std::string(SEMAP_SHARED_DATA_DIR) +
         "/sim_unstructured_annotated/sim_unstructured_annotated_" + std::to_string(i) + ".pcd";
}

std::vector<std::string> lines_of(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class SemapMapCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("semap_map_cli_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(SemapMapCli, WritesQueriesVoxelsAndInsertTime) {
  const auto q = dir_ / "query.txt", v = dir_ / "voxels.csv";
  const CliResult r = run("--method bki --threads 2 --query-out " + q.string() + " --out-voxels " +
                          v.string() + " " + toy(1) + " " + toy(2));
  ASSERT_EQ(r.status, 0) << r.out;
  // The last line is the insertion time.
  const auto last = r.out.substr(r.out.rfind("insert_seconds"));
  EXPECT_EQ(last.find('\n'), last.size() - 1);
  EXPECT_GT(std::stod(last.substr(15)), 0.0);

  const std::size_t points =
      map_io::read_pcd(toy(1)).cloud.size() + map_io::read_pcd(toy(2)).cloud.size();
  const auto queries = lines_of(q);
  ASSERT_EQ(queries.size(), points);
  const auto scan1 = map_io::read_pcd(toy(1)).cloud;
  std::size_t right = 0;
  for (std::size_t i = 0; i < scan1.size(); ++i) {
    const int label = std::stoi(queries[i]);
    ASSERT_GE(label, -1);
    ASSERT_LE(label, 3);
    right += label == scan1.labels[i];
  }
  EXPECT_GT(right, scan1.size() * 8 / 10);

  const auto voxels = lines_of(v);
  ASSERT_GT(voxels.size(), 100u);
  EXPECT_EQ(voxels[0], "x,y,z,label");
  for (std::size_t i = 1; i < voxels.size(); ++i) {
    const int label = std::stoi(voxels[i].substr(voxels[i].rfind(',') + 1));
    ASSERT_TRUE(label >= 1 && label <= 3) << voxels[i];
  }
}

TEST_F(SemapMapCli, ConfigFileSetsParametersAndFlagsOverrideIt) {
  std::ofstream(dir_ / "map.yaml") << "map:\n  method: csm\n  resolution: 0.2\n";
  const CliResult from_file = run("--config " + (dir_ / "map.yaml").string() + " " + toy(1));
  ASSERT_EQ(from_file.status, 0) << from_file.out;
  EXPECT_NE(from_file.out.find("method csm"), std::string::npos);
  const CliResult overridden =
      run("--config " + (dir_ / "map.yaml").string() + " --method bki " + toy(1));
  EXPECT_NE(overridden.out.find("method bki"), std::string::npos);
  std::ofstream(dir_ / "typo.yaml") << "map:\n  resolutoin: 0.2\n";
  const CliResult typo = run("--config " + (dir_ / "typo.yaml").string() + " " + toy(1));
  EXPECT_EQ(typo.status, 1);
  EXPECT_NE(typo.out.find("resolutoin"), std::string::npos) << typo.out;
}

TEST_F(SemapMapCli, BadScanFailsWithFileAndLine) {
  std::ofstream(dir_ / "bad.pcd") << "FIELDS x y z label\nPOINTS 1\nDATA ascii\n1 2\n";
  const CliResult r = run((dir_ / "bad.pcd").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("bad.pcd:4: expected 4 values, found 2"), std::string::npos) << r.out;
  const CliResult bad_method = run("--method gp " + toy(1));
  EXPECT_NE(bad_method.status, 0);
}

}  // namespace
}  // namespace semap::mapping
