// Label images made beforehand (semap-segment's <stem>.labels.png) read back as segmentations.
#include "semap/perception/label_image_segmenter.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace semap::perception {
namespace {

TEST(LabelImageSegmenter, PixelValuesAreMapClassesAndZeroIsNoLabel) {
  cv::Mat ids(2, 3, CV_8UC1);
  ids.at<std::uint8_t>(0, 0) = 0;
  ids.at<std::uint8_t>(0, 1) = 1;
  ids.at<std::uint8_t>(0, 2) = 7;
  ids.at<std::uint8_t>(1, 0) = 3;
  ids.at<std::uint8_t>(1, 1) = 0;
  ids.at<std::uint8_t>(1, 2) = 2;
  cv::Mat bgr;  // as cv::imread(IMREAD_COLOR) gives a grey PNG: the value in every channel
  cv::cvtColor(ids, bgr, cv::COLOR_GRAY2BGR);
  LabelImageSegmenter segmenter(8);
  const Segmentation s = segmenter.segment(bgr);
  EXPECT_EQ(s.num_classes, 8);
  EXPECT_FALSE(s.soft());
  EXPECT_EQ(s.labels.at<std::uint16_t>(0, 0), kNoLabel);
  EXPECT_EQ(s.labels.at<std::uint16_t>(0, 1), 1);
  EXPECT_EQ(s.labels.at<std::uint16_t>(0, 2), 7);
  EXPECT_EQ(s.labels.at<std::uint16_t>(1, 0), 3);
  EXPECT_EQ(s.labels.at<std::uint16_t>(1, 1), kNoLabel);
  EXPECT_FLOAT_EQ(s.confidence.at<float>(1, 2), 1.0f);
}

TEST(LabelImageSegmenter, AnIdBeyondTheMapNamesThePixel) {
  cv::Mat bgr(2, 2, CV_8UC3, cv::Scalar(1, 1, 1));
  bgr.at<cv::Vec3b>(1, 0) = cv::Vec3b(8, 8, 8);
  LabelImageSegmenter segmenter(8);
  try {
    segmenter.segment(bgr);
    FAIL() << "an id of 8 in an 8-class map was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "label image: pixel (0, 1) = 8, the map has classes 0..7");
  }
  EXPECT_THROW(LabelImageSegmenter(1), std::invalid_argument);
  EXPECT_THROW(LabelImageSegmenter(257), std::invalid_argument);
  EXPECT_THROW(segmenter.segment(cv::Mat(2, 2, CV_8UC1)), std::invalid_argument);
}

}  // namespace
}  // namespace semap::perception
