#include "semap/perception/palette_segmenter.hpp"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "segmenter_test_files.hpp"
#include "semap/common/config.hpp"

namespace semap::perception {
namespace {

using testing::TempDir;
using testing::write_text;

cv::Vec3b bgr_of(const cv::Vec3b& rgb) { return {rgb[2], rgb[1], rgb[0]}; }

float probability(const Segmentation& s, int y, int x, int c) {
  return s.probabilities.ptr<float>(y)[x * s.num_classes + c];
}

TEST(PaletteSegmenter, CityscapesPaletteHasTheOfficialClasses) {
  const auto palette = cityscapes_palette();
  ASSERT_EQ(palette.size(), 19u);
  EXPECT_EQ(palette[0].name, "road");
  EXPECT_EQ(palette[0].color, cv::Vec3b(128, 64, 128));
  EXPECT_EQ(palette[6].name, "traffic light");
  EXPECT_EQ(palette[6].color, cv::Vec3b(250, 170, 30));
  EXPECT_EQ(palette[10].name, "sky");
  EXPECT_EQ(palette[10].color, cv::Vec3b(70, 130, 180));
  EXPECT_EQ(palette[13].name, "car");
  EXPECT_EQ(palette[13].color, cv::Vec3b(0, 0, 142));
  EXPECT_EQ(palette[18].name, "bicycle");
  EXPECT_EQ(palette[18].color, cv::Vec3b(119, 11, 32));
  // Default mapping: ground, building, pole; sky and moving classes dropped.
  EXPECT_EQ(palette[0].map_class, 1);
  EXPECT_EQ(palette[2].map_class, 2);
  EXPECT_EQ(palette[5].map_class, 3);
  EXPECT_EQ(palette[10].map_class, kNoLabel);
  EXPECT_EQ(palette[13].map_class, kNoLabel);
}

TEST(PaletteSegmenter, EveryCityscapesColourRoundTrips) {
  CityscapesMapping own_class{};
  for (std::size_t id = 0; id < own_class.size(); ++id) {
    own_class[id] = static_cast<std::uint16_t>(id + 1);
  }
  const auto palette = cityscapes_palette(own_class);
  PaletteSegmenter segmenter(palette, 20);
  cv::Mat image(2, 19, CV_8UC3);
  for (int id = 0; id < 19; ++id) {
    image.at<cv::Vec3b>(0, id) = bgr_of(palette[static_cast<std::size_t>(id)].color);
    image.at<cv::Vec3b>(1, 18 - id) = image.at<cv::Vec3b>(0, id);
  }
  const Segmentation s = segmenter.segment(image);
  for (int id = 0; id < 19; ++id) {
    EXPECT_EQ(s.labels.at<std::uint16_t>(0, id), id + 1) << palette[std::size_t(id)].name;
    EXPECT_EQ(s.labels.at<std::uint16_t>(1, 18 - id), id + 1);
  }
}

TEST(PaletteSegmenter, UnknownAndDroppedColoursGiveNoLabel) {
  PaletteSegmenter segmenter(cityscapes_palette(), 4);
  cv::Mat image(1, 3, CV_8UC3);
  image.at<cv::Vec3b>(0, 0) = bgr_of({128, 64, 129});  // one off road
  image.at<cv::Vec3b>(0, 1) = bgr_of({70, 130, 180});  // sky: dropped
  image.at<cv::Vec3b>(0, 2) = bgr_of({128, 64, 128});  // road
  const Segmentation s = segmenter.segment(image);
  for (int x = 0; x < 2; ++x) {
    EXPECT_EQ(s.labels.at<std::uint16_t>(0, x), kNoLabel);
    EXPECT_EQ(s.confidence.at<float>(0, x), 0.0f);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(probability(s, 0, x, c), 0.0f);
  }
  EXPECT_EQ(s.labels.at<std::uint16_t>(0, 2), 1);
}

TEST(PaletteSegmenter, SoftLabelSpreadsTheRestOverOtherHitClasses) {
  PaletteSegmenter segmenter({{"wall", {9, 9, 9}, 3}}, 5, {.confidence = 0.8f, .soft = true});
  const Segmentation s = segmenter.segment(cv::Mat(2, 2, CV_8UC3, cv::Scalar(9, 9, 9)));
  ASSERT_TRUE(s.soft());
  EXPECT_EQ(s.probabilities.type(), CV_32FC(5));
  EXPECT_EQ(s.labels.at<std::uint16_t>(1, 1), 3);
  EXPECT_FLOAT_EQ(s.confidence.at<float>(1, 1), 0.8f);
  // p_3 = c, p_j = (1 - c) / (K - 2) for j in {1, 2, 4}, p_0 = 0.
  const float expected[] = {0.0f, 0.2f / 3, 0.2f / 3, 0.8f, 0.2f / 3};
  float sum = 0;
  for (int c = 0; c < 5; ++c) {
    EXPECT_NEAR(probability(s, 1, 1, c), expected[c], 1e-6);
    sum += probability(s, 1, 1, c);
  }
  EXPECT_NEAR(sum, 1.0f, 1e-6);
}

TEST(PaletteSegmenter, HardLabelsHaveNoProbabilities) {
  PaletteSegmenter segmenter({{"wall", {9, 9, 9}, 2}}, 3, {.confidence = 0.7f, .soft = false});
  const Segmentation s = segmenter.segment(cv::Mat(2, 3, CV_8UC3, cv::Scalar(9, 9, 9)));
  EXPECT_FALSE(s.soft());
  EXPECT_EQ(s.labels.size(), cv::Size(3, 2));
  EXPECT_EQ(s.labels.at<std::uint16_t>(1, 2), 2);
  EXPECT_FLOAT_EQ(s.confidence.at<float>(1, 2), 0.7f);
}

TEST(PaletteSegmenter, RejectsBadPalettesAndOptions) {
  EXPECT_THROW(PaletteSegmenter({{"a", {1, 2, 3}, 4}}, 4), std::invalid_argument);
  EXPECT_THROW(PaletteSegmenter({{"a", {1, 2, 3}, 1}, {"b", {1, 2, 3}, 2}}, 4),
               std::invalid_argument);
  // c = 0.3 < 1 / (K - 1): another class could be as likely as the label.
  EXPECT_THROW(PaletteSegmenter({{"a", {1, 2, 3}, 1}}, 4, {.confidence = 0.3f}),
               std::invalid_argument);
}

TEST(PaletteSegmenter, WrongInputImageThrows) {
  PaletteSegmenter segmenter(cityscapes_palette(), 4);
  const std::string msg = testing::error_of<std::invalid_argument>(
      [&] { segmenter.segment(cv::Mat(2, 2, CV_8UC4, cv::Scalar(0))); });
  EXPECT_NE(msg.find("got CV_8UC4"), std::string::npos) << msg;
  EXPECT_THROW(segmenter.segment(cv::Mat()), std::invalid_argument);
}

TEST(PaletteSegmenter, LoadsYamlPalette) {
  TempDir dir;
  const auto file = write_text(dir / "palette.yaml",
                               "names: [road, car, tree]\n"
                               "colors: [128, 64, 128,  0, 0, 142,  0, 200, 0]\n"
                               "map_classes: [1, drop, 2]\n");
  const auto palette = load_palette_file(file, 3);
  ASSERT_EQ(palette.size(), 3u);
  EXPECT_EQ(palette[2].name, "tree");
  EXPECT_EQ(palette[2].color, cv::Vec3b(0, 200, 0));
  EXPECT_EQ(palette[1].map_class, kNoLabel);

  PaletteSegmenter segmenter(palette, 3);
  cv::Mat image(1, 3, CV_8UC3);
  image.at<cv::Vec3b>(0, 0) = bgr_of({128, 64, 128});
  image.at<cv::Vec3b>(0, 1) = bgr_of({0, 0, 142});
  image.at<cv::Vec3b>(0, 2) = bgr_of({0, 200, 0});
  const Segmentation s = segmenter.segment(image);
  EXPECT_EQ(s.labels.at<std::uint16_t>(0, 0), 1);
  EXPECT_EQ(s.labels.at<std::uint16_t>(0, 1), kNoLabel);
  EXPECT_EQ(s.labels.at<std::uint16_t>(0, 2), 2);
}

TEST(PaletteSegmenter, BadYamlPaletteNamesFileLineAndKey) {
  TempDir dir;
  const auto error = [&](const std::string& yaml) {
    const auto file = write_text(dir / "palette.yaml", yaml);
    return testing::error_of<common::ConfigError>([&] { load_palette_file(file, 3); });
  };
  const std::string file = (dir / "palette.yaml").string();
  std::string msg = error(
      "names: [road, car]\n"
      "colors: [128, 64, 128, 0, 0, 142]\n"
      "map_classes:\n"
      "  - 1\n"
      "  - 3\n");
  EXPECT_NE(msg.find(file + ":5: key 'map_classes': element 1: expected a map class in 1..2 "
                            "or drop, got '3'"),
            std::string::npos)
      << msg;
  msg = error("names: [road, car]\ncolors: [128, 64, 128, 0, 0, 142]\nmap_classes: [1]\n");
  EXPECT_NE(msg.find(file + ":3: key 'map_classes': 1 entries, expected one per name (2)"),
            std::string::npos)
      << msg;
  msg = error("names: [road, car]\ncolors: [1, 2, 3, 1, 2, 3]\nmap_classes: [1, 2]\n");
  EXPECT_NE(msg.find(file + ":2: key 'colors': element 3: colour of 'car' is already 'road'"),
            std::string::npos)
      << msg;
  msg = error("names: [road]\ncolors: [1, 2, 3]\nmap_classes: [1]\nnum_classes: 3\n");
  EXPECT_NE(msg.find(file + ":4: key 'num_classes': unknown key"), std::string::npos) << msg;
}

}  // namespace
}  // namespace semap::perception
