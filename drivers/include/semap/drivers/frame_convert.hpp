#pragma once

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <optional>

#include "semap/common/messages.hpp"

namespace semap::drivers {

class JpegDecoder;

// V4L2 fourcc of a pipeline pixel format, and back (nullopt for formats the pipeline lacks).
std::uint32_t to_fourcc(common::PixelFormat format);
std::optional<common::PixelFormat> from_fourcc(std::uint32_t fourcc);

// Largest width or height to_mat converts (V4L2 devices stay far below it).
inline constexpr std::uint32_t kMaxImageSide = 16384;

// Converts a captured frame to an OpenCV image: YUYV and MJPEG to CV_8UC3 BGR, GREY to
// CV_8UC1, Z16 to CV_16UC1 (depth units as the device reports them). Raw formats are copied
// out of the frame; an empty Mat means the frame is truncated, its stride is shorter than a
// row of pixels (or YUYV has an odd width, or Z16 an odd stride), a side exceeds kMaxImageSide, the
// JPEG is corrupt or the JPEG's header gives another size than the frame's width and height.
cv::Mat to_mat(const common::ImageFrame& frame, JpegDecoder& jpeg);

// The inverse for raw formats: an image (CV_8UC3 as kBgr24, CV_8UC1 as kGrey, CV_16UC1 as kZ16)
// as a frame, rows packed. Throws std::invalid_argument when the type does not match the format.
common::ImageFrame to_frame(const cv::Mat& image, common::PixelFormat format, common::Stamp stamp,
                            std::uint32_t sequence);
// Bytes a complete raw frame needs (stride * height); 0 for compressed formats.
std::size_t expected_size(const common::ImageFrame& frame);

}  // namespace semap::drivers
