#pragma once

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <span>

namespace semap::drivers {

struct JpegInfo {
  int width = 0;
  int height = 0;
};

// libturbojpeg decompressor handle; one per thread (tjhandle is not thread safe).
class JpegDecoder {
 public:
  JpegDecoder();
  ~JpegDecoder();
  JpegDecoder(const JpegDecoder&) = delete;
  JpegDecoder& operator=(const JpegDecoder&) = delete;

  // Parses the header only; nullopt if the bytes are not a JPEG image.
  std::optional<JpegInfo> header(std::span<const std::uint8_t> jpeg);
  // Most pixels decode_bgr allocates for (8192 x 8192).
  static constexpr std::int64_t kMaxJpegPixels = std::int64_t{8192} * 8192;

  // Decodes to BGR; an empty Mat if the data is corrupt or claims more than kMaxJpegPixels.
  cv::Mat decode_bgr(std::span<const std::uint8_t> jpeg);

 private:
  void* handle_;
};

}  // namespace semap::drivers
