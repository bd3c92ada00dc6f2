// Camera frame conversion: a frame whose header (format, width, height, stride) and bytes come
// from the input goes through drivers::to_mat (YUYV/GREY/Z16/BGR24 copies, MJPEG through
// libturbojpeg). The result is empty or an image of exactly the frame's size and the format's
// type, read only from the frame's bytes (ASan), whatever the header claims.
// Input: format (1 byte), width, height, stride (uint32 LE each), then the frame's bytes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "fuzz_input.hpp"
#include "semap/drivers/frame_convert.hpp"
#include "semap/drivers/jpeg_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using semap::common::PixelFormat;
  semap::fuzz::FuzzInput in(data, size);
  semap::common::ImageFrame frame;
  frame.format = static_cast<PixelFormat>(in.take<std::uint8_t>() % 5);
  frame.width = in.take<std::uint32_t>();
  frame.height = in.take<std::uint32_t>();
  frame.stride = in.take<std::uint32_t>();
  const auto bytes = in.rest();
  frame.data.assign(bytes.begin(), bytes.end());

  static semap::drivers::JpegDecoder jpeg;
  const cv::Mat mat = semap::drivers::to_mat(frame, jpeg);
  if (frame.format != PixelFormat::kMjpeg &&
      semap::drivers::expected_size(frame) !=
          static_cast<std::size_t>(frame.stride) * frame.height) {
    std::abort();
  }
  if (mat.empty()) return 0;
  if (mat.cols != static_cast<int>(frame.width) || mat.rows != static_cast<int>(frame.height)) {
    std::abort();
  }
  int type = CV_8UC3;
  if (frame.format == PixelFormat::kGrey) type = CV_8UC1;
  if (frame.format == PixelFormat::kZ16) type = CV_16UC1;
  if (mat.type() != type || !mat.isContinuous()) std::abort();
  // Touch every pixel: a Mat pointing outside its allocation shows up under ASan here.
  const std::size_t bytes_out = mat.total() * mat.elemSize();
  std::size_t sum = 0;
  for (std::size_t i = 0; i < bytes_out; ++i) sum += mat.data[i];
  if (sum > bytes_out * 255) std::abort();
  return 0;
}
