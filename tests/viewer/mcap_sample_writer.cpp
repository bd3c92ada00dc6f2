// Writes a small MCAP file with semap's writer (drivers::mcap::McapWriter) for the node reader
// test (mcap_read_test.js, @mcap/core): semap's own CDR (dds_idl::serialize_cdr) of odometry,
// a map cloud, an occupancy grid and health reports under their ros2msg schemas, in chunks
// compressed as asked. Test-only, until `semap-onboard --record RUN.mcap` records a run.
//
//   mcap_sample_writer OUT.mcap zstd|lz4|none
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/message_tap.hpp"
#include "semap/dds_idl/ros2msg.hpp"
#include "semap/dds_idl/types.hpp"
#include "semap/drivers/mcap_writer.hpp"

namespace {

using namespace semap;
namespace mcap = drivers::mcap;

dds_idl::msg::Time stamp_at(std::uint64_t ns) {
  dds_idl::msg::Time t{};
  t.sec_ = static_cast<std::int32_t>(ns / 1'000'000'000);
  t.nanosec_ = static_cast<std::uint32_t>(ns % 1'000'000'000);
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s OUT.mcap zstd|lz4|none\n", argv[0]);
    return 2;
  }
  const std::string kind = argv[2];
  mcap::McapWriterOptions options;
  options.compression = kind == "zstd"  ? mcap::Compression::kZstd
                        : kind == "lz4" ? mcap::Compression::kLz4
                                        : mcap::Compression::kNone;
  options.chunk_size = 64 * 1024;  // several chunks from a small file
  mcap::McapWriter writer(argv[1], options);
  const auto channel = [&](const std::string& type, const std::string& topic) {
    const auto schema = writer.add_schema(type, "ros2msg", dds_idl::ros2msg_schema(type));
    return writer.add_channel(schema, topic, "cdr");
  };
  const auto odometry_ch = channel("nav_msgs/msg/Odometry", "/semap/odometry");
  const auto grid_ch = channel("nav_msgs/msg/OccupancyGrid", "/semap/costmap");
  const auto cloud_ch = channel("sensor_msgs/msg/PointCloud2", "/semap/map_cloud");
  const auto health_ch = channel("semap_msgs/msg/Health", "/semap/health");

  std::vector<std::uint8_t> cdr;
  const std::uint64_t t0 = 1'700'000'000'000'000'000ULL;
  char frame_map[] = "map";
  char frame_base[] = "base_link";
  std::uint32_t sequence = 0;
  for (int i = 0; i < 2000; ++i) {  // 10 s of odometry at 200 Hz
    const std::uint64_t t = t0 + static_cast<std::uint64_t>(i) * 5'000'000ULL;
    dds_idl::msg::Odometry odom{};
    odom.header_.stamp_ = stamp_at(t);
    odom.header_.frame_id_ = frame_map;
    odom.child_frame_id_ = frame_base;
    odom.pose_.pose_.position_.x_ = 10.0 * std::cos(i * 0.01);
    odom.pose_.pose_.position_.y_ = 10.0 * std::sin(i * 0.01);
    odom.pose_.pose_.orientation_.w_ = 1.0;
    dds_idl::serialize_cdr(odom, cdr);
    writer.write(odometry_ch, sequence++, t, t, cdr);

    if (i % 200 == 0) {  // 1 Hz: the costmap, the map cloud and the health report
      std::vector<std::int8_t> cells(100 * 80);
      for (std::size_t c = 0; c < cells.size(); ++c)
        cells[c] = static_cast<std::int8_t>(c % 102) - 1;
      dds_idl::msg::OccupancyGrid grid{};
      grid.header_.stamp_ = stamp_at(t);
      grid.header_.frame_id_ = frame_map;
      grid.info_.resolution_ = 0.2f;
      grid.info_.width_ = 100;
      grid.info_.height_ = 80;
      grid.info_.origin_.orientation_.w_ = 1.0;
      grid.data_ = dds_idl::borrow_sequence<dds_sequence_octet>(  // int8 cells as octets
          reinterpret_cast<std::uint8_t*>(cells.data()), cells.size());
      dds_idl::serialize_cdr(grid, cdr);
      writer.write(grid_ch, sequence++, t, t, cdr);

      std::array<char[9], 3> names{"x", "y", "z"};
      std::array<dds_idl::msg::PointField, 3> fields{};
      for (std::size_t f = 0; f < fields.size(); ++f) {
        fields[f].name_ = names[f];
        fields[f].offset_ = static_cast<std::uint32_t>(4 * f);
        fields[f].datatype_ = 7;
        fields[f].count_ = 1;
      }
      std::vector<float> points(3 * 500 * static_cast<std::size_t>(i / 200 + 1));
      for (std::size_t p = 0; p < points.size(); ++p) points[p] = static_cast<float>(p % 97) * 0.2f;
      dds_idl::msg::PointCloud2 cloud{};
      cloud.header_.stamp_ = stamp_at(t);
      cloud.header_.frame_id_ = frame_map;
      cloud.height_ = 1;
      cloud.width_ = static_cast<std::uint32_t>(points.size() / 3);
      cloud.fields_ = dds_idl::borrow_sequence<dds_sequence_sensor_msgs_msg_dds__PointField_>(
          fields.data(), fields.size());
      cloud.point_step_ = 12;
      cloud.row_step_ = 12 * cloud.width_;
      cloud.data_ = dds_idl::borrow_sequence<dds_sequence_uint8>(
          reinterpret_cast<std::uint8_t*>(points.data()), points.size() * sizeof(float));
      cloud.is_dense_ = true;
      dds_idl::serialize_cdr(cloud, cdr);
      writer.write(cloud_ch, sequence++, t, t, cdr);

      std::array<char[16], 2> stage_names{"perception", "mapping"};
      std::array<dds_idl::msg::StageHealth, 2> stages{};
      for (std::size_t s = 0; s < stages.size(); ++s) {
        stages[s].name_ = stage_names[s];
        stages[s].rate_hz_ = 15.0f;
        stages[s].drops_ = s;
        stages[s].latency_p50_ms_ = 40.0f;
        stages[s].latency_p99_ms_ = 80.0f;
      }
      dds_idl::msg::Health health{};
      health.header_.stamp_ = stamp_at(t);
      health.header_.frame_id_ = frame_base;
      health.stages_ = dds_idl::borrow_sequence<dds_sequence_semap_msgs_msg_dds__StageHealth_>(
          stages.data(), stages.size());
      dds_idl::serialize_cdr(health, cdr);
      writer.write(health_ch, sequence++, t, t, cdr);
    }
  }
  writer.close();
  std::printf("%s: %llu messages, %llu bytes\n", argv[1],
              static_cast<unsigned long long>(writer.messages_written()),
              static_cast<unsigned long long>(writer.file_size()));
  return 0;
}
