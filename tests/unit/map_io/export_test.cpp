#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>

#include "semap/map_io/map_export.hpp"
#include "semap/map_io/pcd_io.hpp"
#include "semap/mapping/logodds_map.hpp"

namespace semap::map_io {
namespace {

using namespace semap::mapping;

class Export : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("export_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
    MapParams p;
    p.method = MapMethod::kLogOdds;
    p.resolution = 0.1f;
    p.num_classes = 4;
    LogOddsMap map(p, 1);
    // A floor of class 1 and a wall of class 2, seen from above.
    common::LabeledCloud cloud;
    cloud.origin = Eigen::Vector3f(0.55f, 0.55f, 1.05f);
    for (int x = 0; x < 10; ++x) {
      for (int y = 0; y < 10; ++y) {
        cloud.points.emplace_back(x * 0.1f + 0.05f, y * 0.1f + 0.05f, 0.05f);
        cloud.labels.push_back(1);
      }
      for (int z = 1; z < 5; ++z) {
        cloud.points.emplace_back(x * 0.1f + 0.05f, 0.95f, z * 0.1f + 0.05f);
        cloud.labels.push_back(2);
      }
    }
    for (int i = 0; i < 3; ++i) map.insert(cloud);
    cells_ = occupied_cells(map.layers());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;
  std::vector<OccupiedCell> cells_;
  ClassPalette palette_ = ClassPalette::defaults(4);
};

TEST_F(Export, OccupiedCellsCarryClassAndVariance) {
  // The wall column's top cells hide part of the floor; every hit cell is occupied.
  ASSERT_EQ(cells_.size(), 100u + 40u);
  std::size_t walls = 0;
  for (const auto& c : cells_) {
    EXPECT_EQ(c.label, c.centre.z() > 0.1 ? 2 : 1);
    EXPECT_GT(c.probability, 0.99f);
    EXPECT_NEAR(c.variance, c.probability * (1.0f - c.probability), 1e-6f);
    walls += c.label == 2;
  }
  EXPECT_EQ(walls, 40u);
}

TEST_F(Export, PlyHoldsEveryCellWithColourAndFields) {
  const auto path = dir_ / "cells.ply";
  write_ply(path, cells_, palette_);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const auto end = bytes.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  EXPECT_NE(bytes.find("element vertex 140\n"), std::string::npos);
  EXPECT_NE(bytes.find("property float variance\n"), std::string::npos);
  constexpr std::size_t kRecord = 3 * 4 + 3 + 4 + 4 + 4;
  ASSERT_EQ(bytes.size() - end - 11, cells_.size() * kRecord);
  const char* record = bytes.data() + end + 11;
  for (const auto& c : cells_) {
    float xyz[3];
    std::int32_t label = 0;
    std::memcpy(xyz, record, 12);
    std::memcpy(&label, record + 15, 4);
    EXPECT_NEAR(xyz[2], c.centre.z(), 1e-6);
    EXPECT_EQ(label, c.label);
    const Rgb rgb = palette_.color(c.label);
    EXPECT_EQ(static_cast<std::uint8_t>(record[12]), rgb[0]);
    EXPECT_EQ(static_cast<std::uint8_t>(record[14]), rgb[2]);
    record += kRecord;
  }
}

TEST_F(Export, PcdIsReadBackByThePcdReader) {
  const auto path = dir_ / "cells.pcd";
  write_cells_pcd(path, cells_, palette_);
  const PcdScan scan = read_pcd(path);
  ASSERT_EQ(scan.cloud.size(), cells_.size());
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    EXPECT_TRUE(scan.cloud.points[i].isApprox(cells_[i].centre.cast<float>(), 1e-6f));
    EXPECT_EQ(scan.cloud.labels[i], cells_[i].label);
  }
}

TEST_F(Export, OctomapHasOccupiedColouredCells) {
  const auto path = dir_ / "cells.ot";
  write_octomap(path, cells_, 0.1, palette_);
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(path.string()));
  ASSERT_NE(tree, nullptr);
  auto* color_tree = dynamic_cast<octomap::ColorOcTree*>(tree.get());
  ASSERT_NE(color_tree, nullptr);
  EXPECT_EQ(color_tree->getNumLeafNodes(), cells_.size());
  for (const auto& c : cells_) {
    const auto* node = color_tree->search(c.centre.x(), c.centre.y(), c.centre.z());
    ASSERT_NE(node, nullptr);
    EXPECT_TRUE(color_tree->isNodeOccupied(node));
    EXPECT_EQ(node->getColor().r, palette_.color(c.label)[0]);
    EXPECT_EQ(node->getColor().g, palette_.color(c.label)[1]);
  }
}

TEST_F(Export, TopDownPngsShowTopClassAndLegend) {
  const auto classes = dir_ / "top.png";
  const auto variance = dir_ / "var.png";
  write_top_down_pngs(classes, variance, cells_, 0.1, palette_, {.pixels_per_cell = 5});
  const cv::Mat image = cv::imread(classes.string());
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 10 * 5 + 170);
  // Row y = 9 (the wall, top of the image) shows class 2, the rest of the floor class 1.
  const auto at = [&](int x, int y) { return image.at<cv::Vec3b>(y * 5 + 2, x * 5 + 2); };
  const Rgb wall = palette_.color(2);
  const Rgb floor = palette_.color(1);
  EXPECT_EQ(at(3, 0), cv::Vec3b(wall[2], wall[1], wall[0]));
  EXPECT_EQ(at(3, 5), cv::Vec3b(floor[2], floor[1], floor[0]));
  // The legend has a swatch of each class.
  EXPECT_EQ(image.at<cv::Vec3b>(18, 50 + 18), cv::Vec3b(floor[2], floor[1], floor[0]));
  const cv::Mat heat = cv::imread(variance.string());
  ASSERT_FALSE(heat.empty());
  EXPECT_EQ(heat.size(), image.size());
  EXPECT_THROW(write_top_down_pngs(dir_ / "x.png", "", {}, 0.1, palette_), std::runtime_error);
}

}  // namespace
}  // namespace semap::map_io
