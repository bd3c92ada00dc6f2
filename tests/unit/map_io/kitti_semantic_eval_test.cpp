#include "semap/map_io/kitti_semantic_eval.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "kitti_test_sequence.hpp"
#include "semap/map_io/kitti_iou_table.hpp"

namespace semap::map_io {
namespace {

using testing::KittiTestSequence;
using testing::kRawBuilding;
using testing::kRawCar;
using testing::kRawRoad;
using testing::kRawSidewalk;
using testing::kRawUnlabeled;

constexpr int kCar = 1, kRoad = 9, kBuilding = 13;

// The whitespace-separated fields of the table line that starts with `name`.
std::vector<std::string> table_row(const std::string& table, const std::string& name) {
  std::istringstream lines(table);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::vector<std::string> row{std::istream_iterator<std::string>(fields), {}};
    if (!row.empty() && row[0] == name) return row;
  }
  return {};
}

// Twelve isolated points; truth: 6 road, 3 building, 1 car, 2 unlabelled. Predictions: one
// road point called building, the car called road, one unlabelled point called road and one
// left unlabelled.
class IsolatedPoints : public ::testing::Test {
 protected:
  void SetUp() override {
    files_.write_poses({Eigen::Vector3d::Zero()});
    const std::vector<std::uint32_t> truth{kRawRoad,     kRawRoad, kRawRoad,      kRawRoad,
                                           kRawRoad,     kRawRoad, kRawBuilding,  kRawBuilding,
                                           kRawBuilding, kRawCar,  kRawUnlabeled, kRawUnlabeled};
    const std::vector<std::uint32_t> predicted{
        kRawRoad,     kRawRoad,     kRawRoad,     kRawRoad, kRawRoad, kRawBuilding,
        kRawBuilding, kRawBuilding, kRawBuilding, kRawRoad, kRawRoad, kRawUnlabeled};
    files_.write_scan(0, testing::isolated_points(truth.size()), truth);
    files_.write_labels("predictions", 0, predicted);
    config_.predictions = files_.dir() / "predictions";
  }
  KittiTestSequence files_;
  KittiSemanticConfig config_;
};

TEST_F(IsolatedPoints, TableMatchesTheHandComputedConfusion) {
  const KittiSemanticResult r = evaluate_kitti_semantic(files_.dir(), config_);
  ASSERT_TRUE(r.bad_scans.empty());
  EXPECT_EQ(r.scans, 1u);
  EXPECT_EQ(r.points, 12u);
  EXPECT_EQ(r.unscored_points, 2u);
  EXPECT_EQ(r.unlabeled_inputs, 1u);
  // By hand: road TP 5, FN 1 (to building), FP 1 (the car); building TP 3, FP 1; car FN 1.
  EXPECT_EQ(r.input.total(), 10u);
  EXPECT_EQ(r.input.count(kRoad, kRoad), 5u);
  EXPECT_EQ(r.input.count(kRoad, kBuilding), 1u);
  EXPECT_EQ(r.input.count(kCar, kRoad), 1u);
  EXPECT_EQ(r.input.count(kBuilding, kBuilding), 3u);
  const std::vector<IouTableRow> rows{
      {"input", &r.input}, {"S-CSM", &r.maps.at(0).confusion}, {"S-BKI", &r.maps.at(1).confusion}};
  const std::string table = format_kitti_iou_table(rows);
  const auto input = table_row(table, "input");
  ASSERT_EQ(input.size(), 21u) << table;
  for (int c = 1; c < kKittiClasses; ++c) {
    const std::string expected = c == kRoad       ? "71.4"  // 5 / 7
                                 : c == kBuilding ? "75.0"  // 3 / 4
                                 : c == kCar      ? "0.0"   // 0 / 1
                                                  : "n/a";       // absent from the truth
    EXPECT_EQ(input[static_cast<std::size_t>(c)], expected) << kitti_class_names()[c];
  }
  EXPECT_EQ(input[20], "48.8");  // (5/7 + 3/4 + 0) / 3
  // Every point has a cell and a kernel support of its own, so both maps return the input.
  for (const char* method : {"S-CSM", "S-BKI"}) {
    auto row = table_row(table, method);
    ASSERT_FALSE(row.empty()) << table;
    row[0] = "input";
    EXPECT_EQ(row, input) << table;
  }
}

TEST_F(IsolatedPoints, BadScansAreSkippedCountedAndNamed) {
  files_.write_poses({Eigen::Vector3d::Zero(), {0, 0, 0}, {0, 0, 0}, {0, 0, 0}});
  const auto points = testing::isolated_points(2);
  const std::vector<std::uint32_t> road(2, kRawRoad);
  files_.write_bytes("velodyne/000001.bin", "seventeen bytes..", 17);
  files_.write_labels("labels", 1, road);
  files_.write_labels("predictions", 1, road);
  files_.write_scan(2, points, {kRawRoad});  // one label for two points
  files_.write_labels("predictions", 2, road);
  files_.write_scan(3, points, road);
  files_.write_labels("predictions", 3, {kRawRoad, kRawRoad, kRawRoad});
  const KittiSemanticResult r = evaluate_kitti_semantic(files_.dir(), config_);
  EXPECT_EQ(r.scans, 1u);
  ASSERT_EQ(r.bad_scans.size(), 3u);
  EXPECT_NE(r.bad_scans[0].find("000001.bin: size 17 bytes is not a multiple of 16"),
            std::string::npos)
      << r.bad_scans[0];
  EXPECT_NE(r.bad_scans[1].find("labels/000002.label: 1 labels for 2 points"), std::string::npos)
      << r.bad_scans[1];
  EXPECT_NE(r.bad_scans[2].find("predictions/000003.label: 3 labels for 2 points"),
            std::string::npos)
      << r.bad_scans[2];
  // The range leaves the bad scans out.
  config_.first = 0;
  config_.last = 0;
  EXPECT_TRUE(evaluate_kitti_semantic(files_.dir(), config_).bad_scans.empty());
  config_.first = 3;
  config_.last = 9;
  const KittiSemanticResult tail = evaluate_kitti_semantic(files_.dir(), config_);
  EXPECT_EQ(tail.scans, 0u);
  EXPECT_EQ(tail.bad_scans.size(), 1u);
  config_.first = 4;
  EXPECT_THROW(evaluate_kitti_semantic(files_.dir(), config_), std::invalid_argument);
}

TEST_F(IsolatedPoints, UnreadablePosesAndMissingCalibrationNameTheFile) {
  const auto message = [&] {
    try {
      evaluate_kitti_semantic(files_.dir(), config_);
    } catch (const KittiError& e) {
      return std::string(e.what());
    }
    return std::string("no KittiError");
  };
  std::ofstream(files_.dir() / "calib.txt") << "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n";
  EXPECT_NE(message().find("calib.txt: no Tr: line"), std::string::npos) << message();
  std::filesystem::remove(files_.dir() / "poses.txt");
  EXPECT_NE(message().find("poses.txt: cannot open"), std::string::npos) << message();
  std::ofstream(files_.dir() / "poses.txt") << "1 0 0 0 0 1 0 0 0 0 1 zero\n";
  EXPECT_NE(message().find("poses.txt:1: expected 12 numbers"), std::string::npos) << message();
}

// Road with a sidewalk strip and a building wall, every 0.05 m, seen from three positions.
TEST(KittiSemanticEval, MapsFromNoisyGroundTruthBeatTheirInput) {
  KittiTestSequence files;
  const std::vector<Eigen::Vector3d> positions{{0, 0, 0}, {0.5, 0, 0}, {1.0, 0, 0}};
  files.write_poses(positions);
  std::vector<Eigen::Vector3f> world;
  std::vector<std::uint32_t> labels;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) {
      const float x = 2.0f + 0.05f * static_cast<float>(i),
                  y = -2.5f + 0.05f * static_cast<float>(j);
      world.emplace_back(x, y, -1.5f);
      labels.push_back(y > 1.5f ? kRawSidewalk : kRawRoad);
    }
  }
  for (int j = 0; j < 100; ++j) {
    for (int k = 0; k < 40; ++k) {
      world.emplace_back(7.0f, -2.5f + 0.05f * static_cast<float>(j),
                         -1.45f + 0.05f * static_cast<float>(k));
      labels.push_back(kRawBuilding);
    }
  }
  for (std::size_t s = 0; s < positions.size(); ++s) {
    std::vector<Eigen::Vector3f> sensor;
    for (const auto& p : world) sensor.push_back(p - positions[s].cast<float>());
    files.write_scan(s, sensor, labels);
  }
  KittiSemanticConfig config;
  config.flip_fraction = 0.3;
  const KittiSemanticResult r = evaluate_kitti_semantic(files.dir(), config);
  ASSERT_TRUE(r.bad_scans.empty());
  EXPECT_EQ(r.flipped_labels, 3 * static_cast<std::size_t>(std::llround(0.3 * world.size())));
  const double input = kitti_mean_iou(r.input);
  EXPECT_LT(input, 0.8);
  for (const KittiMapResult& map : r.maps) {
    EXPECT_EQ(map.insert_seconds.size(), 3u);
    EXPECT_GT(map.stats.observed_cells, 0u);
    EXPECT_GT(kitti_mean_iou(map.confusion), input + 0.1) << mapping::to_string(map.method);
  }
}

// A patch of road seen at x = 0, then 100 m away, then at x = 0 again: with a 20 m memory
// radius the first patch goes to the log while the car is away and comes back when it returns,
// so the maps score as the unpaged ones and hold fewer blocks at the end.
TEST(KittiSemanticEval, PagedMapsScoreAsTheWholeMapsAndHoldLess) {
  KittiTestSequence files;
  const std::vector<Eigen::Vector3d> positions{{0, 0, 0}, {100, 0, 0}, {0, 0, 0}};
  files.write_poses(positions);
  std::vector<Eigen::Vector3f> sensor;
  std::vector<std::uint32_t> labels;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) {
      sensor.emplace_back(2.0f + 0.05f * static_cast<float>(i),
                          -1.0f + 0.05f * static_cast<float>(j), -1.5f);
      labels.push_back(j < 30 ? kRawRoad : kRawSidewalk);
    }
  }
  for (std::size_t s = 0; s < positions.size(); ++s) files.write_scan(s, sensor, labels);
  KittiSemanticConfig config;
  config.flip_fraction = 0.2;
  config.query_lag = 0;  // each scan scored where it was taken
  const KittiSemanticResult whole = evaluate_kitti_semantic(files.dir(), config);
  config.memory_radius_m = 20.0;
  config.page_dir = files.dir() / "pages";
  const KittiSemanticResult paged = evaluate_kitti_semantic(files.dir(), config);
  ASSERT_EQ(paged.maps.size(), whole.maps.size());
  for (std::size_t m = 0; m < paged.maps.size(); ++m) {
    const std::string method = mapping::to_string(paged.maps[m].method);
    EXPECT_GT(paged.maps[m].paged_out, 0u) << method;
    EXPECT_GT(paged.maps[m].paged_in, 0u) << method;
    EXPECT_LT(paged.maps[m].stats.blocks, whole.maps[m].stats.blocks) << method;
    EXPECT_EQ(kitti_mean_iou(paged.maps[m].confusion), kitti_mean_iou(whole.maps[m].confusion))
        << method;
    EXPECT_TRUE(std::filesystem::exists(config.page_dir / (method + ".log"))) << method;
  }
  config.page_dir.clear();
  EXPECT_THROW(evaluate_kitti_semantic(files.dir(), config), std::invalid_argument);
}

TEST(KittiIouTable, RefusesRowsOfOtherClassCounts) {
  const mapping::ConfusionMatrix four(4);
  const std::vector<IouTableRow> rows{{"x", &four}};
  EXPECT_THROW(format_kitti_iou_table(rows), std::invalid_argument);
}

}  // namespace
}  // namespace semap::map_io
