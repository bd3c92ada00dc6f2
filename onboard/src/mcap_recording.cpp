#include "semap/onboard/mcap_recording.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/message_tap.hpp"
#include "semap/dds_idl/recording_types.hpp"

namespace semap::onboard {

namespace mcap = drivers::mcap;
using dds_idl::RecordingTopics;

std::string_view image_encoding(common::PixelFormat format) {
  switch (format) {
    case common::PixelFormat::kYuyv:
      return "yuv422_yuy2";
    case common::PixelFormat::kGrey:
      return "mono8";
    case common::PixelFormat::kZ16:
      return "16UC1";
    case common::PixelFormat::kBgr24:
      return "bgr8";
    case common::PixelFormat::kMjpeg:
      break;
  }
  return {};
}

std::optional<common::PixelFormat> pixel_format_of(std::string_view encoding) {
  for (const auto f : {common::PixelFormat::kYuyv, common::PixelFormat::kGrey,
                       common::PixelFormat::kZ16, common::PixelFormat::kBgr24}) {
    if (image_encoding(f) == encoding) return f;
  }
  return std::nullopt;
}

std::optional<std::pair<std::uint32_t, std::uint32_t>> jpeg_size(
    std::span<const std::uint8_t> jpeg) {
  std::size_t at = 2;  // after SOI
  if (jpeg.size() < 4 || jpeg[0] != 0xff || jpeg[1] != 0xd8) return std::nullopt;
  while (at + 4 <= jpeg.size()) {
    if (jpeg[at] != 0xff) return std::nullopt;
    const std::uint8_t marker = jpeg[at + 1];
    if (marker == 0xff) {  // fill byte
      ++at;
      continue;
    }
    const std::size_t length = (std::size_t{jpeg[at + 2]} << 8) | jpeg[at + 3];
    const bool sof =
        marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (sof && at + 9 <= jpeg.size()) {
      const std::uint32_t height = (std::uint32_t{jpeg[at + 5]} << 8) | jpeg[at + 6];
      const std::uint32_t width = (std::uint32_t{jpeg[at + 7]} << 8) | jpeg[at + 8];
      return std::make_pair(width, height);
    }
    at += 2 + length;
  }
  return std::nullopt;
}

bool is_mcap_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, mcap::kMagic.size()> head{};
  if (!in.read(head.data(), head.size())) return false;
  return std::memcmp(head.data(), mcap::kMagic.data(), head.size()) == 0;
}

std::string recorded_config(const std::filesystem::path& path) {
  mcap::McapMessageReader reader(path);
  while (const auto m = reader.next()) {
    if (m->channel.topic != RecordingTopics::kConfig) continue;
    dds_idl::msg::String s{};
    if (!dds_idl::deserialize_cdr(m->message.data, s)) break;
    std::string text = s.data_ != nullptr ? s.data_ : "";
    dds_sample_free(&s, dds_idl::TypeDescriptor<dds_idl::msg::String>::get(), DDS_FREE_CONTENTS);
    return text;
  }
  throw std::runtime_error(path.string() + ": holds no configuration (" + RecordingTopics::kConfig +
                           ")" + (reader.error().empty() ? "" : ": " + reader.error()));
}

namespace {

common::Stamp stamp_of(const dds_idl::msg::Time& t) {
  return common::Stamp(static_cast<std::int64_t>(t.sec_) * 1'000'000'000 +
                       static_cast<std::int64_t>(t.nanosec_));
}

// A decoded sample that frees what Cyclone allocated in it.
template <typename T>
struct Decoded {
  T msg{};
  ~Decoded() { dds_sample_free(&msg, dds_idl::TypeDescriptor<T>::get(), DDS_FREE_CONTENTS); }
};

}  // namespace

McapRecordingReader::McapRecordingReader(const std::filesystem::path& path,
                                         std::int64_t lookahead_ns)
    : path_(path), reader_(path), lookahead_ns_(lookahead_ns) {}

void McapRecordingReader::fail(const std::string& what) {
  if (error_.empty()) error_ = path_.string() + ": " + what;
  ended_ = true;
}

void McapRecordingReader::fill() {
  while (!ended_) {
    std::optional<std::int64_t> earliest;
    const auto consider = [&](const auto& queue) {
      if (!queue.empty()) {
        const auto ns = queue.front().stamp.ns;
        earliest = earliest ? std::min(*earliest, ns) : ns;
      }
    };
    consider(can);
    consider(gnss);
    consider(colour);
    consider(depth);
    if (!can.empty() && !gnss.empty() && !colour.empty() && !depth.empty()) return;
    if (earliest && last_read_ns_ >= *earliest + lookahead_ns_) return;
    read_one();
  }
}

void McapRecordingReader::read_one() {
  const auto view = reader_.next();
  if (!view) {
    ended_ = true;
    if (reader_.status() != mcap::McapReadStatus::kEnd) error_ = reader_.error();
    return;
  }
  const std::string& topic = view->channel.topic;
  const mcap::Message& message = view->message;
  const auto data = std::span<const std::uint8_t>(message.data);
  const auto bad = [&] {
    fail(topic + " message " + std::to_string(reader_.messages()) +
         ": does not decode as its type");
  };
  std::int64_t stamp_ns = 0;
  if (topic == RecordingTopics::kCan) {
    Decoded<dds_idl::msg::CanFrame> m;
    if (!dds_idl::deserialize_cdr(data, m.msg) || m.msg.dlc_ > SEMAP_CAN_MAX_DLEN) return bad();
    Can c;
    c.stamp = stamp_of(m.msg.header_.stamp_);
    c.frame.id = m.msg.id_;
    c.frame.extended = m.msg.is_extended_ ? 1 : 0;
    c.frame.len = m.msg.dlc_;
    std::memcpy(c.frame.data, m.msg.data_, 8);
    c.error_frame = m.msg.is_error_;
    stamp_ns = c.stamp.ns;
    can.push_back(c);
  } else if (topic == RecordingTopics::kGnss) {
    Decoded<dds_idl::msg::GnssBytes> m;
    if (!dds_idl::deserialize_cdr(data, m.msg)) return bad();
    Gnss g;
    g.stamp = stamp_of(m.msg.header_.stamp_);
    g.bytes.assign(m.msg.data_._buffer, m.msg.data_._buffer + m.msg.data_._length);
    stamp_ns = g.stamp.ns;
    gnss.push_back(std::move(g));
  } else if (topic == RecordingTopics::kColour || topic == RecordingTopics::kDepth) {
    Decoded<dds_idl::msg::Image> m;
    if (!dds_idl::deserialize_cdr(data, m.msg)) return bad();
    const auto format = pixel_format_of(m.msg.encoding_ != nullptr ? m.msg.encoding_ : "");
    if (!format)
      return fail(topic + ": unknown encoding " + (m.msg.encoding_ ? m.msg.encoding_ : ""));
    common::ImageFrame f;
    f.stamp = stamp_of(m.msg.header_.stamp_);
    f.sequence = message.sequence;
    f.format = *format;
    f.width = m.msg.width_;
    f.height = m.msg.height_;
    f.stride = m.msg.step_;
    f.data.assign(m.msg.data_._buffer, m.msg.data_._buffer + m.msg.data_._length);
    stamp_ns = f.stamp.ns;
    (topic == RecordingTopics::kDepth ? depth : colour).push_back(std::move(f));
  } else if (topic == RecordingTopics::kColourCompressed ||
             topic == RecordingTopics::kDepthCompressed) {
    Decoded<dds_idl::msg::CompressedImage> m;
    if (!dds_idl::deserialize_cdr(data, m.msg)) return bad();
    common::ImageFrame f;
    f.stamp = stamp_of(m.msg.header_.stamp_);
    f.sequence = message.sequence;
    f.format = common::PixelFormat::kMjpeg;
    f.data.assign(m.msg.data_._buffer, m.msg.data_._buffer + m.msg.data_._length);
    if (const auto size = jpeg_size(f.data)) {
      f.width = size->first;
      f.height = size->second;
    }
    stamp_ns = f.stamp.ns;
    (topic == RecordingTopics::kDepthCompressed ? depth : colour).push_back(std::move(f));
  } else {
    return;  // the outputs and the configuration: not played
  }
  last_read_ns_ = std::max(last_read_ns_, stamp_ns);
}

}  // namespace semap::onboard
