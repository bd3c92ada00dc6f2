// Runs build/bin/semap-dataset semantickitti as a user would: its table, figures, errors and exit
// codes.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "kitti_test_sequence.hpp"
#include "support/cli_run.hpp"

namespace semap::map_io {
namespace {

using test_support::CliResult;
using testing::KittiTestSequence;

CliResult run(const std::string& args) { return test_support::run_cli(SEMAP_DATASET_EXE, args); }

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class SemanticKittiCli : public ::testing::Test {
 protected:
  void SetUp() override {
    files_.write_poses({Eigen::Vector3d::Zero(), {0.2, 0, 0}});
    const std::vector<std::uint32_t> labels{testing::kRawRoad, testing::kRawBuilding,
                                            testing::kRawCar};
    for (std::size_t s = 0; s < 2; ++s) {
      files_.write_scan(s, testing::isolated_points(labels.size()), labels);
    }
  }
  std::string sequence() const { return "semantickitti --sequence " + files_.dir().string(); }
  KittiTestSequence files_;
};

TEST_F(SemanticKittiCli, PrintsTheTableTimingAndMemory) {
  const CliResult r = run(sequence() + " --threads 2 --flip 0 --progress-seconds 0.000001");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "threads 2")) << r.out;
  EXPECT_TRUE(has(r.out, "ell 0.3")) << r.out;
  EXPECT_TRUE(has(r.out, "traffic-sign average")) << r.out;
  EXPECT_TRUE(has(r.out, "\ninput ")) << r.out;
  EXPECT_TRUE(has(r.out, "\nS-CSM ")) << r.out;
  EXPECT_TRUE(has(r.out, "\nS-BKI ")) << r.out;
  EXPECT_TRUE(has(r.out, "insert_ms S-BKI median")) << r.out;
  EXPECT_TRUE(has(r.out, "peak_memory_mib")) << r.out;
  EXPECT_TRUE(has(r.out, "scans 2 points 6")) << r.out;
  EXPECT_TRUE(has(r.out, "semap-dataset semantickitti: 2/2 scans")) << r.out;
  EXPECT_TRUE(has(r.out, "ETA 0 s")) << r.out;
  const CliResult bki = run(sequence() + " --method bki --first 1 --ell 0.2");
  ASSERT_EQ(bki.status, 0) << bki.out;
  EXPECT_FALSE(has(bki.out, "S-CSM")) << bki.out;
  EXPECT_TRUE(has(bki.out, "ell 0.2")) << bki.out;
  EXPECT_TRUE(has(bki.out, "scans 1 points 3")) << bki.out;
  EXPECT_FALSE(has(bki.out, "ETA")) << bki.out;  // no progress line within 5 s
}

TEST_F(SemanticKittiCli, BadInputNamesTheFileAndSetsTheExitStatus) {
  files_.write_bytes("velodyne/000001.bin", "0123456789", 10);
  const CliResult skipped = run(sequence());
  EXPECT_EQ(skipped.status, 2) << skipped.out;
  EXPECT_TRUE(has(skipped.out, "skipped " + (files_.dir() / "velodyne/000001.bin").string()))
      << skipped.out;
  EXPECT_TRUE(has(skipped.out, "skipped_scans 1")) << skipped.out;
  std::ofstream(files_.dir() / "calib.txt") << "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n";
  const CliResult no_calib = run(sequence());
  EXPECT_EQ(no_calib.status, 1) << no_calib.out;
  EXPECT_TRUE(has(no_calib.out, "calib.txt: no Tr: line")) << no_calib.out;
  EXPECT_NE(run(sequence() + " --method all").status, 0);
  EXPECT_NE(run(sequence() + " --num-classes 4").status, 0);
}

}  // namespace
}  // namespace semap::map_io
