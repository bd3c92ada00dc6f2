#include "semap/perception/segmentation_views.hpp"

#include <gtest/gtest.h>

#include "segmenter_test_files.hpp"

namespace semap::perception {
namespace {

// A 2x3 segmentation into K = 4 classes, one pixel without a label.
Segmentation small_segmentation() {
  Segmentation s;
  s.num_classes = 4;
  s.labels = (cv::Mat_<std::uint16_t>(2, 3) << 1, 1, 3, kNoLabel, 2, 1);
  return s;
}

ModelCard card_with(const std::vector<std::pair<std::string, std::uint16_t>>& classes) {
  ModelCard card;
  card.num_map_classes = 4;
  std::uint8_t shade = 10;
  for (const auto& [name, map_class] : classes) {
    card.classes.push_back({name, cv::Vec3b(shade, 0, 0), map_class});
    shade += 10;
  }
  return card;
}

TEST(SegmentationViews, StylesJoinTheModelClassesFeedingEachMapClass) {
  const auto styles =
      map_class_styles(card_with({{"road", 1}, {"sky", kNoLabel}, {"grass", 1}, {"car", 3}}));
  ASSERT_EQ(styles.size(), 4u);
  EXPECT_EQ(styles[0].name, "no label");
  EXPECT_EQ(styles[1].name, "road+grass");
  EXPECT_EQ(styles[1].color, cv::Vec3b(10, 0, 0));  // the first feeding class's
  EXPECT_EQ(styles[2].name, "class 2");             // nothing feeds it
  EXPECT_EQ(styles[3].name, "car");
  EXPECT_EQ(styles[3].color, cv::Vec3b(40, 0, 0));
}

TEST(SegmentationViews, LabelImageWritesNoLabelAsZero) {
  const cv::Mat ids = label_image(small_segmentation());
  ASSERT_EQ(ids.type(), CV_8UC1);
  ASSERT_EQ(ids.size(), cv::Size(3, 2));
  EXPECT_EQ(ids.at<std::uint8_t>(0, 2), 3);
  EXPECT_EQ(ids.at<std::uint8_t>(1, 0), 0);
  EXPECT_EQ(ids.at<std::uint8_t>(1, 1), 2);
  Segmentation wide = small_segmentation();
  wide.num_classes = 257;
  EXPECT_NE(testing::error_of<std::invalid_argument>([&] { label_image(wide); }).find("8-bit"),
            std::string::npos);
}

TEST(SegmentationViews, OverlayBlendsLabelledPixelsOnly) {
  const Segmentation s = small_segmentation();
  std::vector<MapClassStyle> styles{
      {"no label", {0, 0, 0}}, {"a", {255, 0, 0}}, {"b", {0, 255, 0}}, {"c", {0, 0, 255}}};
  const cv::Mat bgr(2, 3, CV_8UC3, cv::Scalar(100, 50, 0));
  const cv::Mat out = class_overlay(bgr, s, styles);
  EXPECT_EQ(out.at<cv::Vec3b>(1, 0), cv::Vec3b(100, 50, 0));   // no label: the image
  EXPECT_EQ(out.at<cv::Vec3b>(0, 0), cv::Vec3b(50, 25, 128));  // halfway to red (b, g, r)
  EXPECT_EQ(out.at<cv::Vec3b>(0, 2), cv::Vec3b(178, 25, 0));   // halfway to blue
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(100, 50, 0));   // input untouched
}

TEST(SegmentationViews, SharesCountEveryPixelOnce) {
  const auto shares = class_shares(small_segmentation());
  ASSERT_EQ(shares.size(), 4u);
  EXPECT_DOUBLE_EQ(shares[0], 1.0 / 6);
  EXPECT_DOUBLE_EQ(shares[1], 3.0 / 6);
  EXPECT_DOUBLE_EQ(shares[2], 1.0 / 6);
  EXPECT_DOUBLE_EQ(shares[3], 1.0 / 6);
}

}  // namespace
}  // namespace semap::perception
