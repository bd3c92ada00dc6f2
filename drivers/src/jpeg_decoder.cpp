#include "semap/drivers/jpeg_decoder.hpp"

#include <turbojpeg.h>

#include <stdexcept>

namespace semap::drivers {

JpegDecoder::JpegDecoder() : handle_(tjInitDecompress()) {
  if (!handle_) throw std::runtime_error("tjInitDecompress failed");
}

JpegDecoder::~JpegDecoder() { tjDestroy(handle_); }

std::optional<JpegInfo> JpegDecoder::header(std::span<const std::uint8_t> jpeg) {
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (jpeg.empty() ||
      tjDecompressHeader3(handle_, jpeg.data(), static_cast<unsigned long>(jpeg.size()), &width,
                          &height, &subsampling, &colorspace) != 0) {
    return std::nullopt;
  }
  return JpegInfo{width, height};
}

cv::Mat JpegDecoder::decode_bgr(std::span<const std::uint8_t> jpeg) {
  const auto info = header(jpeg);
  // The header alone sizes the allocation: refuse sizes no camera sends (a 12-byte header can
  // claim 65535 x 65535).
  if (!info || info->width <= 0 || info->height <= 0 ||
      static_cast<std::int64_t>(info->width) * info->height > kMaxJpegPixels) {
    return {};
  }
  cv::Mat out(info->height, info->width, CV_8UC3);
  // Warnings (e.g. a few missing bytes at the end, common with MJPEG webcams) still give a
  // usable image; only hard errors reject the frame.
  if (tjDecompress2(handle_, jpeg.data(), static_cast<unsigned long>(jpeg.size()), out.data,
                    info->width, static_cast<int>(out.step), info->height, TJPF_BGR,
                    TJFLAG_FASTDCT) != 0 &&
      tjGetErrorCode(handle_) == TJERR_FATAL) {
    return {};
  }
  return out;
}

}  // namespace semap::drivers
