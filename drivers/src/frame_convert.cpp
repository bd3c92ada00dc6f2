#include "semap/drivers/frame_convert.hpp"

#include <linux/videodev2.h>

#include <cstring>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "semap/drivers/jpeg_decoder.hpp"

namespace semap::drivers {

using common::PixelFormat;

std::uint32_t to_fourcc(PixelFormat format) {
  switch (format) {
    case PixelFormat::kYuyv:
      return V4L2_PIX_FMT_YUYV;
    case PixelFormat::kMjpeg:
      return V4L2_PIX_FMT_MJPEG;
    case PixelFormat::kGrey:
      return V4L2_PIX_FMT_GREY;
    case PixelFormat::kZ16:
      return V4L2_PIX_FMT_Z16;
    case PixelFormat::kBgr24:
      return V4L2_PIX_FMT_BGR24;
  }
  return 0;
}

std::optional<PixelFormat> from_fourcc(std::uint32_t fourcc) {
  switch (fourcc) {
    case V4L2_PIX_FMT_YUYV:
      return PixelFormat::kYuyv;
    case V4L2_PIX_FMT_MJPEG:
    case V4L2_PIX_FMT_JPEG:
      return PixelFormat::kMjpeg;
    case V4L2_PIX_FMT_GREY:
      return PixelFormat::kGrey;
    case V4L2_PIX_FMT_Z16:
      return PixelFormat::kZ16;
    case V4L2_PIX_FMT_BGR24:
      return PixelFormat::kBgr24;
    default:
      return std::nullopt;
  }
}

std::size_t expected_size(const common::ImageFrame& frame) {
  if (frame.format == PixelFormat::kMjpeg) return 0;
  return static_cast<std::size_t>(frame.stride) * frame.height;
}

namespace {

// Bytes of one pixel in the frame (YUYV: 2 per pixel, 4 per pixel pair).
std::size_t bytes_per_pixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::kYuyv:
    case PixelFormat::kZ16:
      return 2;
    case PixelFormat::kGrey:
      return 1;
    case PixelFormat::kBgr24:
      return 3;
    case PixelFormat::kMjpeg:
      break;
  }
  return 0;
}

}  // namespace

cv::Mat to_mat(const common::ImageFrame& frame, JpegDecoder& jpeg) {
  if (frame.width > kMaxImageSide || frame.height > kMaxImageSide) return {};
  if (frame.format == PixelFormat::kMjpeg) {
    // The JPEG's own header decides the allocation: it must describe the frame's image.
    const auto info = jpeg.header(frame.data);
    if (!info || static_cast<std::uint32_t>(info->width) != frame.width ||
        static_cast<std::uint32_t>(info->height) != frame.height) {
      return {};
    }
    return jpeg.decode_bgr(frame.data);
  }
  // A row shorter than the pixels it must hold would make the rows overlap (or, with stride
  // 0, read past the frame); YUYV packs pixel pairs; Z16 rows start on a 16-bit sample.
  if (frame.width == 0 || frame.height == 0 ||
      frame.stride < frame.width * bytes_per_pixel(frame.format) ||
      (frame.format == PixelFormat::kYuyv && frame.width % 2 != 0) ||
      (frame.format == PixelFormat::kZ16 && frame.stride % 2 != 0) ||
      frame.data.size() < expected_size(frame)) {
    return {};
  }
  // cv::Mat views the frame's bytes with its stride; the conversions below copy.
  auto* data = const_cast<std::uint8_t*>(frame.data.data());
  const int rows = static_cast<int>(frame.height);
  const int cols = static_cast<int>(frame.width);
  switch (frame.format) {
    case PixelFormat::kYuyv: {
      const cv::Mat yuyv(rows, cols, CV_8UC2, data, frame.stride);
      cv::Mat bgr;
      cv::cvtColor(yuyv, bgr, cv::COLOR_YUV2BGR_YUYV);
      return bgr;
    }
    case PixelFormat::kGrey:
      return cv::Mat(rows, cols, CV_8UC1, data, frame.stride).clone();
    case PixelFormat::kZ16:
      return cv::Mat(rows, cols, CV_16UC1, data, frame.stride).clone();
    case PixelFormat::kBgr24:
      return cv::Mat(rows, cols, CV_8UC3, data, frame.stride).clone();
    case PixelFormat::kMjpeg:
      break;
  }
  return {};
}

common::ImageFrame to_frame(const cv::Mat& image, common::PixelFormat format, common::Stamp stamp,
                            std::uint32_t sequence) {
  const int type = format == common::PixelFormat::kBgr24  ? CV_8UC3
                   : format == common::PixelFormat::kGrey ? CV_8UC1
                   : format == common::PixelFormat::kZ16  ? CV_16UC1
                                                          : -1;
  if (type < 0 || image.type() != type) {
    throw std::invalid_argument("to_frame: the image's type does not match the pixel format");
  }
  common::ImageFrame f;
  f.stamp = stamp;
  f.sequence = sequence;
  f.format = format;
  f.width = static_cast<std::uint32_t>(image.cols);
  f.height = static_cast<std::uint32_t>(image.rows);
  f.stride = static_cast<std::uint32_t>(image.cols * image.elemSize());
  f.data.resize(static_cast<std::size_t>(f.stride) * f.height);
  for (int v = 0; v < image.rows; ++v) {
    std::memcpy(f.data.data() + static_cast<std::size_t>(v) * f.stride, image.ptr(v), f.stride);
  }
  return f;
}

}  // namespace semap::drivers
