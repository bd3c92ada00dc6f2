#pragma once

#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/drivers/mcap_message_reader.hpp"
#include "semap/firmware_bridge/can_frame.h"

namespace semap::onboard {

// sensor_msgs/msg/Image encodings of the camera formats: yuv422_yuy2, mono8, 16UC1, bgr8
// (MJPEG goes into a CompressedImage, format "jpeg": empty here).
std::string_view image_encoding(common::PixelFormat format);
std::optional<common::PixelFormat> pixel_format_of(std::string_view encoding);
// The width and height in a JPEG's frame header (SOF0..SOF15 but DHT, JPG, DAC).
std::optional<std::pair<std::uint32_t, std::uint32_t>> jpeg_size(
    std::span<const std::uint8_t> jpeg);

// Whether `path` is an MCAP file (its magic); a directory is the old recording format.
bool is_mcap_file(const std::filesystem::path& path);

// The configuration file an MCAP recording holds (/semap/recording/config). Throws
// std::runtime_error naming the file when it holds none.
std::string recorded_config(const std::filesystem::path& path);

// The inputs of an MCAP recording (semap-onboard --record FILE.mcap) for a replay, decoded
// from their CDR and merged in stamp order. The file holds them in arrival order (what the
// recorder's queue received when), which is each stream's stamp order but not the streams'
// merged order: a camera frame arrives after the IMU samples stamped later than it. fill()
// reads ahead until the earliest front is known to be the earliest record: each of the four
// streams has one waiting, or the file has been read `lookahead_ns` past it, or it ended.
class McapRecordingReader {
 public:
  struct Can {
    common::Stamp stamp;
    SemapCanFrame frame{};
    bool error_frame = false;
  };
  struct Gnss {
    common::Stamp stamp;
    std::vector<std::uint8_t> bytes;
  };

  explicit McapRecordingReader(const std::filesystem::path& path,
                               std::int64_t lookahead_ns = 2'000'000'000);

  void fill();
  std::deque<Can> can;
  std::deque<Gnss> gnss;
  std::deque<common::ImageFrame> colour, depth;

  // Empty while the file reads as it should; otherwise what stopped it, naming the file:
  // "<file>: truncated at byte N: ..." for a recording cut off (a crash, power loss, a disk
  // that was full when it was closed), which plays up to its last whole chunk.
  const std::string& error() const { return error_; }
  bool ended() const { return ended_; }
  std::uint64_t messages() const { return reader_.messages(); }

 private:
  void read_one();
  void fail(const std::string& what);

  std::filesystem::path path_;
  drivers::mcap::McapMessageReader reader_;
  std::int64_t lookahead_ns_;
  std::int64_t last_read_ns_ = 0;  // the latest input stamp read
  bool ended_ = false;
  std::string error_;
};

}  // namespace semap::onboard
