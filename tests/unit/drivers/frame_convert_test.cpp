#include "semap/drivers/frame_convert.hpp"

#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <turbojpeg.h>

#include <opencv2/core.hpp>

#include "semap/drivers/jpeg_decoder.hpp"

namespace semap::drivers {
namespace {

using common::ImageFrame;
using common::PixelFormat;

ImageFrame raw_frame(PixelFormat format, std::uint32_t w, std::uint32_t h, std::uint32_t bpp,
                     std::uint32_t padding = 0) {
  ImageFrame f;
  f.format = format;
  f.width = w;
  f.height = h;
  f.stride = w * bpp + padding;
  f.data.assign(static_cast<std::size_t>(f.stride) * h, 0);
  return f;
}

TEST(FrameConvert, FourccRoundTrip) {
  for (auto f : {PixelFormat::kYuyv, PixelFormat::kMjpeg, PixelFormat::kGrey, PixelFormat::kZ16,
                 PixelFormat::kBgr24}) {
    EXPECT_EQ(from_fourcc(to_fourcc(f)), f);
  }
  EXPECT_EQ(from_fourcc(V4L2_PIX_FMT_NV12), std::nullopt);
}

TEST(FrameConvert, YuyvGreyLevelsBecomeBgrGrey) {
  auto f = raw_frame(PixelFormat::kYuyv, 4, 2, 2);
  for (std::size_t i = 0; i < f.data.size(); i += 2) {
    f.data[i] = 180;      // Y
    f.data[i + 1] = 128;  // U/V neutral
  }
  JpegDecoder jpeg;
  const cv::Mat bgr = to_mat(f, jpeg);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  ASSERT_EQ(bgr.size(), cv::Size(4, 2));
  const auto px = bgr.at<cv::Vec3b>(1, 3);
  EXPECT_NEAR(px[0], 180, 25);  // BT.601 limited-range scaling lifts 180 a little
  EXPECT_EQ(px[0], px[1]);
  EXPECT_EQ(px[1], px[2]);
}

TEST(FrameConvert, GreyAndZ16HonourTheStride) {
  auto g = raw_frame(PixelFormat::kGrey, 3, 2, 1, 5);
  g.data[g.stride + 2] = 77;
  auto z = raw_frame(PixelFormat::kZ16, 3, 2, 2, 2);
  const std::uint16_t depth = 1234;
  std::memcpy(&z.data[z.stride + 4], &depth, 2);
  JpegDecoder jpeg;
  const cv::Mat gm = to_mat(g, jpeg);
  ASSERT_EQ(gm.type(), CV_8UC1);
  EXPECT_EQ(gm.at<std::uint8_t>(1, 2), 77);
  const cv::Mat zm = to_mat(z, jpeg);
  ASSERT_EQ(zm.type(), CV_16UC1);
  EXPECT_EQ(zm.at<std::uint16_t>(1, 2), 1234);
}

TEST(FrameConvert, TruncatedRawFrameGivesEmptyMat) {
  auto f = raw_frame(PixelFormat::kGrey, 8, 8, 1);
  f.data.resize(f.data.size() - 1);
  JpegDecoder jpeg;
  EXPECT_TRUE(to_mat(f, jpeg).empty());
}

TEST(FrameConvert, MjpegDecodesWithTurbojpegAndRejectsGarbage) {
  // Encode a known image with libturbojpeg itself.
  cv::Mat src(16, 24, CV_8UC3, cv::Scalar(30, 120, 220));
  tjhandle enc = tjInitCompress();
  unsigned char* jpeg_buf = nullptr;
  unsigned long jpeg_size = 0;
  ASSERT_EQ(tjCompress2(enc, src.data, src.cols, static_cast<int>(src.step), src.rows, TJPF_BGR,
                        &jpeg_buf, &jpeg_size, TJSAMP_444, 95, 0),
            0);
  ImageFrame f;
  f.format = PixelFormat::kMjpeg;
  f.width = 24;
  f.height = 16;
  f.data.assign(jpeg_buf, jpeg_buf + jpeg_size);
  tjFree(jpeg_buf);
  tjDestroy(enc);

  JpegDecoder jpeg;
  const auto info = jpeg.header(f.data);
  ASSERT_TRUE(info);
  EXPECT_EQ(info->width, 24);
  const cv::Mat bgr = to_mat(f, jpeg);
  ASSERT_EQ(bgr.size(), cv::Size(24, 16));
  const auto px = bgr.at<cv::Vec3b>(8, 12);
  EXPECT_NEAR(px[0], 30, 4);
  EXPECT_NEAR(px[1], 120, 4);
  EXPECT_NEAR(px[2], 220, 4);

  std::vector<std::uint8_t> garbage(200, 0x55);
  EXPECT_FALSE(jpeg.header(garbage));
  f.data = garbage;
  EXPECT_TRUE(to_mat(f, jpeg).empty());
}

}  // namespace
}  // namespace semap::drivers
