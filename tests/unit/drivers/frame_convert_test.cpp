#include "semap/drivers/frame_convert.hpp"

#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <turbojpeg.h>

#include <array>
#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <string>

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

// Saturated patches: a U/V or R/B swap moves at least one channel of each by >= 150 levels.
struct Rgb {
  int r, g, b;
  const char* name;
};
constexpr std::array<Rgb, 6> kSaturated = {{{255, 0, 0, "red"},
                                            {0, 255, 0, "green"},
                                            {0, 0, 255, "blue"},
                                            {255, 255, 0, "yellow"},
                                            {0, 255, 255, "cyan"},
                                            {255, 0, 255, "magenta"}}};

// BT.601 R'G'B' -> Y'CbCr, limited ("studio") range as a UVC/V4L2 camera sends YUYV:
// E'y = 0.299 R + 0.587 G + 0.114 B; Y = 16 + 219 E'y, Cb = 128 + 224 (B - E'y) / 1.772,
// Cr = 128 + 224 (R - E'y) / 1.402 (R, G, B, E'y in 0..1).
std::array<std::uint8_t, 3> bt601_ycbcr(const Rgb& c) {
  const double r = c.r / 255.0, g = c.g / 255.0, b = c.b / 255.0;
  const double ey = 0.299 * r + 0.587 * g + 0.114 * b;
  const auto q = [](double v) { return static_cast<std::uint8_t>(std::lround(v)); };
  return {q(16 + 219 * ey), q(128 + 224 * (b - ey) / 1.772), q(128 + 224 * (r - ey) / 1.402)};
}

void expect_colour(const cv::Vec3b& bgr, const Rgb& c, int tolerance, const std::string& where) {
  EXPECT_NEAR(bgr[2], c.r, tolerance) << c.name << " red channel " << where;
  EXPECT_NEAR(bgr[1], c.g, tolerance) << c.name << " green channel " << where;
  EXPECT_NEAR(bgr[0], c.b, tolerance) << c.name << " blue channel " << where;
}

TEST(FrameConvert, YuyvSaturatedColoursMatchBt601PerChannel) {
  // One 8-pixel patch per colour (4 YUYV pairs), 3 rows, 6 bytes of row padding.
  constexpr std::uint32_t kPatch = 8;
  auto f = raw_frame(PixelFormat::kYuyv, kPatch * kSaturated.size(), 3, 2, 6);
  for (std::uint32_t row = 0; row < f.height; ++row) {
    for (std::size_t i = 0; i < kSaturated.size(); ++i) {
      const auto [y, cb, cr] = bt601_ycbcr(kSaturated[i]);
      for (std::uint32_t pair = 0; pair < kPatch / 2; ++pair) {
        // Y0 U Y1 V (V4L2_PIX_FMT_YUYV)
        std::uint8_t* p = &f.data[row * f.stride + (i * kPatch + 2 * pair) * 2];
        p[0] = y;
        p[1] = cb;
        p[2] = y;
        p[3] = cr;
      }
    }
  }
  JpegDecoder jpeg;
  const cv::Mat bgr = to_mat(f, jpeg);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  ASSERT_EQ(bgr.size(), cv::Size(static_cast<int>(f.width), 3));
  for (std::size_t i = 0; i < kSaturated.size(); ++i) {
    for (int row = 0; row < 3; ++row) {
      for (std::uint32_t x = 0; x < kPatch; ++x) {
        const int col = static_cast<int>(i * kPatch + x);
        // Rounding of Y/Cb/Cr to 8 bits and of the 1.164 / 1.596 gains: a few levels.
        expect_colour(bgr.at<cv::Vec3b>(row, col), kSaturated[i], 6,
                      "at row " + std::to_string(row) + " col " + std::to_string(col));
      }
    }
  }
}

TEST(FrameConvert, MjpegSaturatedColoursSurviveEncodeAndDecode) {
  // 16x16 patches (one 4:2:0 MCU each) in BGR, encoded by libturbojpeg with the chroma
  // subsamplings cameras use; each patch's centre must keep its colour channel by channel.
  constexpr int kPatch = 16;
  cv::Mat src(kPatch, kPatch * static_cast<int>(kSaturated.size()), CV_8UC3);
  for (std::size_t i = 0; i < kSaturated.size(); ++i) {
    const Rgb& c = kSaturated[i];
    src(cv::Rect(static_cast<int>(i) * kPatch, 0, kPatch, kPatch)).setTo(cv::Scalar(c.b, c.g, c.r));
  }
  for (const int sampling : {TJSAMP_422, TJSAMP_420, TJSAMP_444}) {
    tjhandle enc = tjInitCompress();
    unsigned char* jpeg_buf = nullptr;
    unsigned long jpeg_size = 0;
    ASSERT_EQ(tjCompress2(enc, src.data, src.cols, static_cast<int>(src.step), src.rows, TJPF_BGR,
                          &jpeg_buf, &jpeg_size, sampling, 95, 0),
              0);
    ImageFrame f;
    f.format = PixelFormat::kMjpeg;
    f.width = static_cast<std::uint32_t>(src.cols);
    f.height = static_cast<std::uint32_t>(src.rows);
    f.data.assign(jpeg_buf, jpeg_buf + jpeg_size);
    tjFree(jpeg_buf);
    tjDestroy(enc);

    JpegDecoder jpeg;
    const cv::Mat bgr = to_mat(f, jpeg);
    ASSERT_EQ(bgr.type(), CV_8UC3);
    ASSERT_EQ(bgr.size(), src.size());
    for (std::size_t i = 0; i < kSaturated.size(); ++i) {
      // The 8x8 centre of the patch: away from the chroma edges with the neighbours.
      for (int y = 4; y < 12; ++y) {
        for (int x = 4; x < 12; ++x) {
          expect_colour(bgr.at<cv::Vec3b>(y, static_cast<int>(i) * kPatch + x), kSaturated[i], 12,
                        "sampling " + std::to_string(sampling));
        }
      }
    }
  }
}

// Found by frame_convert_fuzz (in 11 runs): a stride shorter than a row made cv::Mat throw,
// and stride 0 (cv::Mat's "rows are packed") read past the frame's bytes.
TEST(FrameConvert, StrideShorterThanARowGivesEmptyMat) {
  JpegDecoder jpeg;
  auto grey = raw_frame(PixelFormat::kGrey, 8, 8, 1);
  grey.stride = 7;
  EXPECT_TRUE(to_mat(grey, jpeg).empty());
  auto bgr = raw_frame(PixelFormat::kBgr24, 4, 2, 3);
  bgr.stride = 0;
  bgr.data.clear();
  EXPECT_TRUE(to_mat(bgr, jpeg).empty());
  auto yuyv = raw_frame(PixelFormat::kYuyv, 3, 2, 2);  // YUYV holds pixel pairs
  EXPECT_TRUE(to_mat(yuyv, jpeg).empty());
  // Found by frame_convert_fuzz: an odd Z16 stride made cv::Mat throw.
  auto z16 = raw_frame(PixelFormat::kZ16, 2, 2, 2, 1);
  EXPECT_TRUE(to_mat(z16, jpeg).empty());
  auto huge = raw_frame(PixelFormat::kGrey, 1, 1, 1);
  huge.width = kMaxImageSide + 1;
  EXPECT_TRUE(to_mat(huge, jpeg).empty());
}

// Issue 20, asserted by frame_convert_fuzz: the JPEG header alone sized the decoded image (a
// few bytes can claim 65535 x 65535); now it must match the frame's width and height.
TEST(FrameConvert, MjpegWhoseHeaderDiffersFromTheFrameGivesEmptyMat) {
  cv::Mat src(16, 24, CV_8UC3, cv::Scalar(30, 120, 220));
  tjhandle enc = tjInitCompress();
  unsigned char* jpeg_buf = nullptr;
  unsigned long jpeg_size = 0;
  ASSERT_EQ(tjCompress2(enc, src.data, src.cols, static_cast<int>(src.step), src.rows, TJPF_BGR,
                        &jpeg_buf, &jpeg_size, TJSAMP_444, 95, 0),
            0);
  ImageFrame f;
  f.format = PixelFormat::kMjpeg;
  f.data.assign(jpeg_buf, jpeg_buf + jpeg_size);
  tjFree(jpeg_buf);
  tjDestroy(enc);
  JpegDecoder jpeg;
  f.width = 24;
  f.height = 16;
  EXPECT_EQ(to_mat(f, jpeg).size(), cv::Size(24, 16));
  f.height = 8;
  EXPECT_TRUE(to_mat(f, jpeg).empty());
  f.width = 0;
  f.height = 0;
  EXPECT_TRUE(to_mat(f, jpeg).empty());
}

}  // namespace
}  // namespace semap::drivers
