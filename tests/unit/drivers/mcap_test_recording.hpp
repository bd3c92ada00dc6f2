#pragma once
// A synthetic robot recording for the MCAP tests: several schemas and channels (one without
// schema, one without messages), messages of mixed sizes with log times mostly rising.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "semap/drivers/mcap_writer.hpp"

namespace semap::drivers::mcap::test_recording {

struct SentMessage {
  std::uint16_t channel_id;
  std::uint32_t sequence;
  std::uint64_t log_time;
  std::uint64_t publish_time;
  Bytes data;
};

inline Bytes read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Bytes that compress like a depth image: 16-bit little-endian pixels rising along each
// 320-pixel row, with two bits of noise.
inline Bytes payload(std::size_t size, std::uint32_t seed) {
  Bytes out(size);
  std::uint32_t x = seed * 2654435761u + 1;
  for (std::size_t i = 0; i + 1 < size; i += 2) {
    x = x * 1664525u + 1013904223u;
    const auto pixel = static_cast<std::uint16_t>(1000 + (i / 2) % 320 / 2 + (x >> 30));
    out[i] = static_cast<std::uint8_t>(pixel);
    out[i + 1] = static_cast<std::uint8_t>(pixel >> 8);
  }
  return out;
}

// Declares `channels` channels (schemas 1..3 in turn, the last without schema, plus one that
// never gets a message) and writes `count` messages; returns what was written.
inline std::vector<SentMessage> write_recording(McapWriter& writer, int channels, int count,
                                                std::size_t max_size) {
  const std::uint16_t schemas[] = {
      writer.add_schema("sensor_msgs/msg/Imu", "ros2msg", "std_msgs/Header header\n"),
      writer.add_schema("sensor_msgs/msg/CompressedImage", "ros2msg", "string format\n"),
      writer.add_schema("can_msgs/msg/Frame", "ros2msg", "uint32 id\nuint8[] data\n")};
  std::vector<std::uint16_t> ids;
  for (int c = 0; c < channels; ++c) {
    const std::uint16_t schema = c == channels - 1 ? 0 : schemas[c % 3];
    ids.push_back(writer.add_channel(schema, "/sensor/" + std::to_string(c), "cdr",
                                     {{"offered_qos_profiles", "- history: 3\n"}}));
  }
  writer.add_channel(schemas[0], "/never/published", "cdr");
  std::vector<SentMessage> sent;
  std::vector<std::uint32_t> sequence(ids.size(), 0);
  for (int i = 0; i < count; ++i) {
    const std::size_t c = static_cast<std::size_t>(i * 7 + i / 5) % ids.size();
    // Every tenth message is logged a little out of order, as merged sensor streams are.
    const std::uint64_t log_time = 1'000'000'000ull + static_cast<std::uint64_t>(i) * 1'000'000 -
                                   (i % 10 == 3 ? 1'500'000 : 0);
    const std::size_t size = static_cast<std::size_t>(i * 131) % (max_size + 1);
    SentMessage m{ids[c], sequence[c]++, log_time, log_time - 200, payload(size, i)};
    writer.write(m.channel_id, m.sequence, m.log_time, m.publish_time, m.data);
    sent.push_back(std::move(m));
  }
  return sent;
}

}  // namespace semap::drivers::mcap::test_recording
