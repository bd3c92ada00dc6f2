// Runs build/bin/semap-segment as a user would: the shipped card on real images (from
// ../shared/data/real/, skipped with a message where absent), its output files and exit codes,
// and --check on a good and on a broken card.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "support/cli_run.hpp"

namespace {

namespace fs = std::filesystem;

using semap::test_support::CliResult;

const fs::path kCard = fs::path(SEMAP_SOURCE_DIR) / "models" / "semap-seg.yaml";
const fs::path kTum = fs::path(SEMAP_SHARED_DATA_DIR) / "real" / "tum_pair" / "TUM_color.png";
const fs::path kRedwood =
    fs::path(SEMAP_SHARED_DATA_DIR) / "real" / "redwood" / "color" / "00000.jpg";

CliResult run(const std::string& args) {
  return semap::test_support::run_cli(SEMAP_SEGMENT_EXE, args);
}

class SemapSegmentCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("semap_segment_cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  static void require_images() {
    if (!fs::exists(kTum) || !fs::exists(kRedwood)) {
      GTEST_SKIP() << "real images not found: " << kTum << ", " << kRedwood;
    }
  }
  fs::path dir_;
};

TEST_F(SemapSegmentCli, WritesLabelsAndOverlayAtEachImagesSize) {
  require_images();
  if (IsSkipped()) return;
  const fs::path out = dir_ / "out";
  const CliResult r = run("--card " + kCard.string() + " " + kTum.string() + " " +
                          kRedwood.string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out;
  for (const std::string stem : {"TUM_color", "00000"}) {
    const cv::Mat labels =
        cv::imread((out / (stem + ".labels.png")).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat overlay =
        cv::imread((out / (stem + ".overlay.png")).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(labels.empty()) << stem << "\n" << r.out;
    ASSERT_FALSE(overlay.empty()) << stem;
    EXPECT_EQ(labels.type(), CV_8UC1);
    EXPECT_EQ(overlay.type(), CV_8UC3);
    EXPECT_EQ(labels.size(), cv::Size(640, 480)) << stem;
    EXPECT_EQ(overlay.size(), cv::Size(640, 480)) << stem;
    double max_id = 0;
    cv::minMaxLoc(labels, nullptr, &max_id);
    EXPECT_LE(max_id, 7) << "the shipped card feeds map classes 1..7";
  }
  // Per image: the size, the time, then the class shares.
  EXPECT_NE(r.out.find("TUM_color.png: 640x480, "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" ms -> "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" %\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dnn segmenter: "), std::string::npos) << r.out;
}

TEST_F(SemapSegmentCli, JsonHasOneEntryPerImageWithItsShares) {
  require_images();
  if (IsSkipped()) return;
  const CliResult r =
      run("--card " + kCard.string() + " " + kTum.string() + " --json --out " + dir_.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out.front(), '{') << r.out;
  EXPECT_NE(r.out.find("\"width\":640,\"height\":480,\"segment_ms\":"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("{\"id\":1,\"name\":\"road\",\"share\":"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("{\"id\":7,\"name\":\"car\",\"share\":"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"no_label\":"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"failed\":0}"), std::string::npos) << r.out;
}

TEST_F(SemapSegmentCli, UnreadableImageIsNamedAndFailsTheRun) {
  require_images();
  if (IsSkipped()) return;
  std::ofstream(dir_ / "broken.png") << "not a png";
  const CliResult r = run("--card " + kCard.string() + " " + (dir_ / "broken.png").string() + " " +
                          kTum.string() + " --out " + dir_.string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("broken.png: not an image OpenCV reads"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir_ / "TUM_color.labels.png")) << "the other images still run";
}

TEST_F(SemapSegmentCli, CheckReportsShapesAndForwardTime) {
  const CliResult r = run("--check " + kCard.string() + " --repeat 2");
  ASSERT_EQ(r.status, 0) << r.out;
  // The shipped network runs at 320x240 and gives logits at a quarter of that.
  EXPECT_NE(r.out.find("input    : [1, 3, 240, 320] (card: 320x240, rgb)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("output   : [1, 8, 60, 80] (card: [1, 8, h, w]"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("threads  : 2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" ms median of 2"), std::string::npos) << r.out;
}

TEST_F(SemapSegmentCli, CheckFailsWithExitTwoOnABrokenCard) {
  CliResult r = run("--check " + (dir_ / "missing.yaml").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find((dir_ / "missing.yaml").string()), std::string::npos) << r.out;

  // The shipped card next to a damaged network.
  fs::copy_file(kCard, dir_ / "semap-seg.yaml");
  std::ofstream(dir_ / "semap-seg.onnx") << "\x08\x01 damaged in transit";
  r = run("--check " + (dir_ / "semap-seg.yaml").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("model card " + (dir_ / "semap-seg.yaml").string()), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("semap-seg.onnx' (onnx) does not load: "), std::string::npos) << r.out;

  // A card whose class count is not the network's.
  std::ifstream in(kCard);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string sky = "70, 130, 180]";
  ASSERT_NE(text.find(sky), std::string::npos);
  text.replace(text.find(sky), sky.size(), "70, 130, 180, 1, 2, 3]");
  text.replace(text.find("car, sky]"), 9, "car, sky, extra]");
  fs::copy_file(fs::path(SEMAP_SOURCE_DIR) / "models" / "semap-seg.onnx", dir_ / "real.onnx");
  text.replace(text.find("model: semap-seg.onnx"), 21, "model: real.onnx");
  std::ofstream(dir_ / "nine.yaml") << text;
  r = run("--check " + (dir_ / "nine.yaml").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("[1, 9, h, w]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("gives [1, 8, 60, 80]"), std::string::npos) << r.out;
}

}  // namespace
