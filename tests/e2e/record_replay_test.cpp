// semap-onboard --record RUN.mcap on the simulated rig, then the recording replayed (rig.kind:
// replay): as fast as possible it must give the recorded run's trajectory (within 1 mm) and map
// (the same occupied cells and classes); at recorded pace, with the GNSS bytes through a pty to
// the real driver, nearly the same; a recording cut off (a crash) plays up to its last whole
// chunk and says so; semap-can extracts its CAN frames as a candump log. The plain
// maths (map.engine: plain, estimator.covariance_window: 1) replayed as fast as possible gives
// the defaults' trajectory and map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "semap/common/map_grid.hpp"
#include "semap/dds_idl/message_tap.hpp"
#include "semap/dds_idl/recording_types.hpp"
#include "semap/drivers/mcap_message_reader.hpp"
#include "semap/drivers/stream_log.hpp"
#include "semap/firmware_bridge/candump_log.h"
#include "semap/firmware_bridge/candump_reader.hpp"
#include "semap/map_io/map_export.hpp"
#include "semap/mapping/smap_io.hpp"
#include "semap/onboard/mcap_recording.hpp"
#include "support/cli_run.hpp"

namespace {

namespace fs = std::filesystem;
using semap::test_support::run_cli;

const std::string kOnboard = SEMAP_ONBOARD;
const std::string kCan = SEMAP_CAN;

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void replace(std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << "config/sim.yaml lacks: " << from;
  text.replace(at, from.size(), to);
}

// The line of the run's summary that starts with `prefix`.
std::string line_of(const std::string& out, const std::string& prefix) {
  const auto at = out.find(prefix);
  if (at == std::string::npos) return {};
  return out.substr(at, out.find('\n', at) - at);
}

// The number after `prefix` in the run's output (-1 when absent).
long long figure(const std::string& out, const std::string& prefix) {
  const auto at = out.find(prefix);
  if (at == std::string::npos) return -1;
  return std::atoll(out.c_str() + at + prefix.size());
}

struct Pose {
  double x, y, z;
};
std::map<std::string, Pose> read_trajectory(const fs::path& path) {
  std::map<std::string, Pose> poses;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string stamp, x, y, z;
    std::getline(fields, stamp, ',');
    std::getline(fields, x, ',');
    std::getline(fields, y, ',');
    std::getline(fields, z, ',');
    poses[stamp] = {std::stod(x), std::stod(y), std::stod(z)};
  }
  return poses;
}

// Position differences at the stamps both trajectories hold, sorted.
std::vector<double> differences(const std::map<std::string, Pose>& a,
                                const std::map<std::string, Pose>& b) {
  std::vector<double> d;
  for (const auto& [stamp, p] : a) {
    const auto it = b.find(stamp);
    if (it == b.end()) continue;
    const Pose& q = it->second;
    d.push_back(std::sqrt((p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y) +
                          (p.z - q.z) * (p.z - q.z)));
  }
  std::sort(d.begin(), d.end());
  return d;
}

std::vector<semap::map_io::OccupiedCell> cells_of(const fs::path& smap) {
  return semap::map_io::occupied_cells(semap::mapping::read_smap(smap).map);
}

// Occupied cells of `a` that `b` holds with the same class, as a fraction of `a`'s.
double shared_fraction(const std::vector<semap::map_io::OccupiedCell>& a,
                       const std::vector<semap::map_io::OccupiedCell>& b) {
  std::map<std::tuple<long, long, long>, int> labels;
  const auto key = [](const Eigen::Vector3d& c) {
    return std::make_tuple(std::lround(c.x() * 100), std::lround(c.y() * 100),
                           std::lround(c.z() * 100));
  };
  for (const auto& cell : b) labels[key(cell.centre)] = cell.label;
  std::size_t same = 0;
  for (const auto& cell : a) {
    const auto it = labels.find(key(cell.centre));
    if (it != labels.end() && it->second == cell.label) ++same;
  }
  return a.empty() ? 0.0 : static_cast<double>(same) / static_cast<double>(a.size());
}

class RecordReplay : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("semap_record_replay_" + std::to_string(::getpid())));
    fs::create_directories(*dir_);
    // A light run the 2-core test machine keeps up with: 320x240 frames at 5 Hz painted in
    // class colours and the palette segmenter; no DDS.
    std::string config = slurp(fs::path(SEMAP_SOURCE_DIR) / "config/sim.yaml");
    replace(config, "duration_s: 40", "duration_s: 25");
    replace(config, "camera_image: rgb", "camera_image: classes");
    replace(config, "  width: 640\n  height: 480\n  fps: 15",
            "  width: 320\n  height: 240\n  fps: 5");
    replace(config, "  kind: onnx", "  kind: palette\n#");
    replace(config, "  model_card: models/semap-seg.yaml", "");
    replace(config, "save_path: build/sim_map.smap",
            "save_path: " + (*dir_ / "live.smap").string());
    replace(config, "dds:\n", "dds:\n  enabled: false\n");
    std::ofstream(*dir_ / "live.yaml") << config;
    live_ = new semap::test_support::CliResult(
        run_cli(kOnboard, "--config " + (*dir_ / "live.yaml").string() + " --record " +
                              rec().string() + " --trajectory " + (*dir_ / "live.csv").string()));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete live_;
  }
  void SetUp() override {
    ASSERT_EQ(live_->status, 0) << live_->out;
    // Replay equality needs a recorded run that lost nothing on the way to the map: every frame
    // taken was mapped, but for those the filter had not reached when the run stopped.
    ASSERT_EQ(figure(live_->out, "ring drops       : imu "), 0) << live_->out;
    const std::string perception = line_of(live_->out, "perception       : ");
    ASSERT_EQ(figure(perception, "perception       : "),
              figure(live_->out, "mapping          : ") + figure(perception, " bad, "))
        << live_->out;
    ASSERT_NE(live_->out.find(" 0 passed over"), std::string::npos) << live_->out;
  }
  static fs::path rec() { return *dir_ / "rec.mcap"; }

  static fs::path* dir_;
  static semap::test_support::CliResult* live_;
};
fs::path* RecordReplay::dir_ = nullptr;
semap::test_support::CliResult* RecordReplay::live_ = nullptr;

TEST_F(RecordReplay, TheRecordingHoldsEveryStream) {
  namespace dds = semap::dds_idl;
  const std::string& out = live_->out;
  semap::drivers::mcap::McapMessageReader reader(rec());
  std::map<std::string, long long> counts;
  long long gnss_bytes = 0, error_frames = 0;
  std::string config;
  while (const auto m = reader.next()) {
    const std::string& topic = m->channel.topic;
    ++counts[topic];
    ASSERT_NE(m->schema, nullptr) << topic;
    EXPECT_EQ(m->schema->encoding, "ros2msg");
    EXPECT_EQ(m->channel.message_encoding, "cdr");
    if (topic == dds::RecordingTopics::kCan) {
      EXPECT_EQ(m->schema->name, "can_msgs/msg/Frame");
      dds::msg::CanFrame f{};
      ASSERT_TRUE(dds::deserialize_cdr(m->message.data, f));
      EXPECT_STREQ(f.header_.frame_id_, "sim");
      EXPECT_EQ(f.dlc_, 8);
      // The log time is the driver's stamp.
      EXPECT_EQ(m->message.log_time,
                static_cast<std::uint64_t>(f.header_.stamp_.sec_) * 1'000'000'000ull +
                    f.header_.stamp_.nanosec_);
      error_frames += f.is_error_ ? 1 : 0;
      dds_sample_free(&f, dds::TypeDescriptor<dds::msg::CanFrame>::get(), DDS_FREE_CONTENTS);
    } else if (topic == dds::RecordingTopics::kGnss) {
      dds::msg::GnssBytes g{};
      ASSERT_TRUE(dds::deserialize_cdr(m->message.data, g));
      gnss_bytes += g.data_._length;
      dds_sample_free(&g, dds::TypeDescriptor<dds::msg::GnssBytes>::get(), DDS_FREE_CONTENTS);
    } else if (topic == dds::RecordingTopics::kColour || topic == dds::RecordingTopics::kDepth) {
      dds::msg::Image image{};
      ASSERT_TRUE(dds::deserialize_cdr(m->message.data, image));
      EXPECT_EQ(image.width_, 320u);
      EXPECT_EQ(image.height_, 240u);
      const std::string encoding = image.encoding_;
      EXPECT_EQ(encoding, topic == dds::RecordingTopics::kDepth ? "16UC1" : "bgr8");
      EXPECT_EQ(image.data_._length, image.step_ * image.height_);
      dds_sample_free(&image, dds::TypeDescriptor<dds::msg::Image>::get(), DDS_FREE_CONTENTS);
    } else if (topic == dds::RecordingTopics::kConfig) {
      dds::msg::String text{};
      ASSERT_TRUE(dds::deserialize_cdr(m->message.data, text));
      config = text.data_;
      dds_sample_free(&text, dds::TypeDescriptor<dds::msg::String>::get(), DDS_FREE_CONTENTS);
    }
  }
  EXPECT_EQ(reader.status(), semap::drivers::mcap::McapReadStatus::kEnd) << reader.error();
  const long long frames = counts[dds::RecordingTopics::kCan];
  EXPECT_EQ(frames, figure(out, "recording        : " + rec().string() + ": "));
  EXPECT_EQ(error_frames, 0);
  // 3 frames per sample of the semap profile.
  EXPECT_EQ(frames, 3 * figure(out, "estimation       : ")) << out;
  // The GNSS port's bytes, all the driver read.
  EXPECT_EQ(gnss_bytes, figure(out, "fixes, ")) << out;
  // Camera frames, every one the perception stage took.
  EXPECT_EQ(counts[dds::RecordingTopics::kColour], figure(out, "perception       : "));
  EXPECT_EQ(counts[dds::RecordingTopics::kDepth], figure(out, "perception       : "));
  EXPECT_EQ(config, slurp(*dir_ / "live.yaml"));
  // No DDS in this run: no outputs.
  EXPECT_EQ(counts.size(), 5u);
}

// semap-can extracts the CAN frames as a candump -L log: can-utils read it (log2asc), and
// semap-can decodes it to the IMU samples the robot estimated with.
TEST_F(RecordReplay, SemapCanExtractsACandumpLog) {
  const fs::path log = *dir_ / "imu.log";
  const auto extract =
      run_cli(kCan, "--from-mcap " + rec().string() + " --candump " + log.string());
  ASSERT_EQ(extract.status, 0) << extract.out;
  std::ifstream imu(log);
  semap::firmware_bridge::CandumpReader candump(imu, "imu.log");
  long long frames = 0;
  while (const auto r = candump.next()) {
    EXPECT_STREQ(r->interface, "sim");
    ++frames;
  }
  EXPECT_EQ(candump.error(), "");
  EXPECT_EQ(frames, figure(live_->out, "recording        : " + rec().string() + ": "));
  if (fs::exists("/usr/bin/log2asc")) {
    const auto asc = run_cli("/usr/bin/log2asc", "-I " + log.string() + " sim");
    ASSERT_EQ(asc.status, 0) << asc.out.substr(0, 500);
    long long rx = 0;
    for (std::size_t at = asc.out.find(" Rx "); at != std::string::npos;
         at = asc.out.find(" Rx ", at + 1)) {
      ++rx;
    }
    EXPECT_EQ(rx, frames);
  }
  // The log decodes to the samples the robot had: semap-can --input, and the MCAP directly.
  const auto from_log = run_cli(kCan, "--input " + log.string() + " --json");
  const auto from_mcap = run_cli(kCan, "--from-mcap " + rec().string() + " --json");
  ASSERT_EQ(from_log.status, 0) << from_log.out.substr(0, 500);
  ASSERT_EQ(from_mcap.status, 0) << from_mcap.out.substr(0, 500);
  long long samples = 0;
  for (std::size_t at = from_log.out.find("{\"class\":\"IMU\""); at != std::string::npos;
       at = from_log.out.find("{\"class\":\"IMU\"", at + 1)) {
    ++samples;
  }
  EXPECT_EQ(samples, figure(live_->out, "estimation       : ")) << from_log.out.substr(0, 500);
  EXPECT_EQ(from_log.out, from_mcap.out);
}

// Each cell of a .smap by its global cell coordinates: its evidence per channel.
std::map<std::tuple<int, int, int>, std::vector<float>> evidence_of(const fs::path& smap) {
  const auto map = semap::mapping::read_smap(smap).map;
  const auto& params = map.params();
  const semap::common::MapGrid grid = params.grid();
  const auto channels = static_cast<std::size_t>(params.channels());
  const int side = params.cells_per_side();
  std::map<std::tuple<int, int, int>, std::vector<float>> cells;
  std::vector<float> block;
  for (const auto& index : map.block_keys()) {
    map.fused_block(index, block);
    for (int c = 0; c < side * side * side; ++c) {
      const auto cell = grid.cell_of_local(index, c);
      const auto first = block.begin() + static_cast<std::ptrdiff_t>(c * channels);
      cells[{cell.x(), cell.y(), cell.z()}] = {first,
                                               first + static_cast<std::ptrdiff_t>(channels)};
    }
  }
  return cells;
}

TEST_F(RecordReplay, AsFastAsPossibleItRepeatsTheRun) {
  const auto r = run_cli(kOnboard, "--replay " + rec().string() + " --pace fast --save " +
                                       (*dir_ / "fast.smap").string() + " --trajectory " +
                                       (*dir_ / "fast.csv").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(figure(r.out, "estimation       : "), figure(live_->out, "estimation       : "));
  // Every record went back in.
  const std::string recorded = line_of(live_->out, "recording        : ");
  const std::string replayed = line_of(r.out, "replay           : ");
  EXPECT_EQ(figure(replayed, "replay           : "), figure(recorded, rec().string() + ": "))
      << recorded << "\n"
      << replayed;
  EXPECT_EQ(figure(replayed, "IMU samples, "), figure(recorded, "CAN frames, "));
  EXPECT_EQ(figure(replayed, "GNSS reads, "), figure(recorded, "bytes), "));

  const auto live = read_trajectory(*dir_ / "live.csv");
  const auto fast = read_trajectory(*dir_ / "fast.csv");
  ASSERT_GT(live.size(), 4000u);
  EXPECT_EQ(fast.size(), live.size());
  const auto d = differences(live, fast);
  ASSERT_EQ(d.size(), live.size()) << "the replay's stamps differ from the recording's";
  EXPECT_LE(d.back(), 1e-3);

  const auto live_cells = cells_of(*dir_ / "live.smap");
  const auto fast_cells = cells_of(*dir_ / "fast.smap");
  ASSERT_GT(live_cells.size(), 1000u);
  ASSERT_EQ(fast_cells.size(), live_cells.size());
  for (std::size_t i = 0; i < live_cells.size(); ++i) {
    ASSERT_LE((fast_cells[i].centre - live_cells[i].centre).norm(), 1e-9) << "cell " << i;
    ASSERT_EQ(fast_cells[i].label, live_cells[i].label) << "cell " << i;
  }
}

// Through the pty the driver stamps the fixes with its own read times, as on a robot, so the
// filter sees GNSS a few hundred microseconds off the recording's stamps. On a loaded machine
// the replay's writer or the driver's reader is now and then scheduled 100 ms late, and that one
// fix pulls the pose by speed x delay: the median and the 99th percentile hold the run to the
// recording, the maximum only to the same road.
TEST_F(RecordReplay, AtRecordedPaceTheGnssGoesThroughAPty) {
  const auto r = run_cli(kOnboard, "--replay " + rec().string() + " --save " +
                                       (*dir_ / "paced.smap").string() + " --trajectory " +
                                       (*dir_ / "paced.csv").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(figure(r.out, "gnss driver      : "), figure(live_->out, "gnss driver      : "))
      << r.out;
  const auto live = read_trajectory(*dir_ / "live.csv");
  const auto d = differences(live, read_trajectory(*dir_ / "paced.csv"));
  ASSERT_GT(d.size(), live.size() * 9 / 10);
  const double median = d[d.size() / 2];
  const double p99 = d[d.size() * 99 / 100];
  std::printf(
      "recorded pace vs the recorded run: position difference median %.2f mm, p99 %.1f mm, max "
      "%.1f mm\n",
      1e3 * median, 1e3 * p99, 1e3 * d.back());
  EXPECT_LE(median, 0.01);
  EXPECT_LE(p99, 0.5);
  EXPECT_LE(d.back(), 2.0);
  const double shared =
      shared_fraction(cells_of(*dir_ / "live.smap"), cells_of(*dir_ / "paced.smap"));
  std::printf("occupied cells of the recorded run's map found with the same class: %.3f\n", shared);
  EXPECT_GE(shared, 0.9);
}

TEST_F(RecordReplay, ARecordingCutOffPlaysUpToItsLastWholeChunk) {
  // The file cut off at 70 % (a crash, a power loss): no summary, the last chunk torn.
  const fs::path cut = *dir_ / "cut.mcap";
  fs::copy_file(rec(), cut, fs::copy_options::overwrite_existing);
  fs::resize_file(cut, fs::file_size(cut) * 7 / 10);
  const auto r = run_cli(kOnboard, "--replay " + cut.string() + " --pace fast --save " +
                                       (*dir_ / "cut.smap").string() + " --trajectory " +
                                       (*dir_ / "cut.csv").string());
  EXPECT_EQ(r.status, 0) << r.out;
  const std::string replayed = line_of(r.out, "replay           : ");
  EXPECT_NE(replayed.find("damaged: " + cut.string() + ": truncated at byte "), std::string::npos)
      << r.out;
  // Every stream up to the cut: fewer samples and frames, the same ones as far as they go.
  const long long samples = figure(r.out, "estimation       : ");
  EXPECT_GT(samples, 1000);
  EXPECT_LT(samples, figure(live_->out, "estimation       : "));
  const long long colour_frames = figure(replayed, "GNSS reads, ");
  EXPECT_GT(colour_frames, 0);
  EXPECT_LT(colour_frames,
            figure(line_of(live_->out, "perception       : "), "perception       : "));
  const auto live = read_trajectory(*dir_ / "live.csv");
  const auto d = differences(live, read_trajectory(*dir_ / "cut.csv"));
  ASSERT_GT(d.size(), 1000u);
  EXPECT_LE(d.back(), 1e-3);

  // Cut inside the first chunk: nothing to play, said so.
  fs::resize_file(cut, 4096);
  const auto nothing = run_cli(kOnboard, "--config " + (*dir_ / "live.yaml").string() +
                                             " --replay " + cut.string() + " --pace fast");
  EXPECT_NE(nothing.status, 0);
  EXPECT_NE(nothing.out.find("truncated at byte"), std::string::npos) << nothing.out;
}

// The recording of the older format (a directory: candump log, stream logs, config) still
// replays, for one release: the MCAP recording's inputs written in that format give the same
// trajectory.
TEST_F(RecordReplay, TheOlderDirectoryFormatStillReplays) {
  const fs::path dir = *dir_ / "rec-dir";
  fs::create_directories(dir);
  {
    std::ofstream imu(dir / "imu.log");
    semap::drivers::StreamLogWriter gnss(dir / "gnss.log", semap::drivers::StreamLogKind::kBytes);
    semap::drivers::StreamLogWriter colour(dir / "colour.log",
                                           semap::drivers::StreamLogKind::kFrames);
    semap::drivers::StreamLogWriter depth(dir / "depth.log",
                                          semap::drivers::StreamLogKind::kFrames);
    semap::onboard::McapRecordingReader reader(rec());
    while (!reader.ended() || !reader.can.empty() || !reader.gnss.empty() ||
           !reader.colour.empty() || !reader.depth.empty()) {
      reader.fill();
      for (const auto& c : reader.can) {
        SemapCandumpRecord r{};
        r.seconds = static_cast<std::uint64_t>(c.stamp.ns / 1'000'000'000);
        r.microseconds = static_cast<std::uint32_t>((c.stamp.ns % 1'000'000'000) / 1'000);
        std::strcpy(r.interface, "sim");
        r.kind = c.error_frame ? SEMAP_CANDUMP_ERROR : SEMAP_CANDUMP_DATA;
        r.frame = c.frame;
        imu << semap::firmware_bridge::format_candump_line(r);
      }
      for (const auto& g : reader.gnss) gnss.write_bytes(g.stamp, g.bytes);
      for (const auto& f : reader.colour) colour.write_frame(f);
      for (const auto& f : reader.depth) depth.write_frame(f);
      reader.can.clear();
      reader.gnss.clear();
      reader.colour.clear();
      reader.depth.clear();
    }
    ASSERT_EQ(reader.error(), "");
  }
  fs::copy_file(*dir_ / "live.yaml", dir / "config.yaml");
  const auto r = run_cli(kOnboard, "--replay " + dir.string() + " --pace fast --save " +
                                       (*dir_ / "dir.smap").string() + " --trajectory " +
                                       (*dir_ / "dir.csv").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(figure(r.out, "estimation       : "), figure(live_->out, "estimation       : "));
  const auto live = read_trajectory(*dir_ / "live.csv");
  const auto d = differences(live, read_trajectory(*dir_ / "dir.csv"));
  ASSERT_EQ(d.size(), live.size());
  EXPECT_LE(d.back(), 1e-3);
}

// The definitions the fast paths are tested against, selected by configuration, on the recorded
// drive: the S-BKI update as the paper writes it (map.engine: plain) and the per-step covariance
// propagation (estimator.covariance_window: 1), against the defaults (tiled engine, 32-step
// window), both replayed as fast as possible.
TEST_F(RecordReplay, ThePlainMathsGiveTheDefaultsRun) {
  std::string config = slurp(*dir_ / "live.yaml");  // the configuration the recording holds
  replace(config, "engine: tiled", "engine: plain");
  replace(config, "covariance_window: 32", "covariance_window: 1");
  std::ofstream(*dir_ / "plain.yaml") << config;
  const auto defaults = run_cli(kOnboard, "--replay " + rec().string() + " --pace fast --save " +
                                              (*dir_ / "defaults.smap").string() +
                                              " --trajectory " + (*dir_ / "defaults.csv").string());
  ASSERT_EQ(defaults.status, 0) << defaults.out;
  const auto plain = run_cli(kOnboard, "--config " + (*dir_ / "plain.yaml").string() +
                                           " --replay " + rec().string() + " --pace fast --save " +
                                           (*dir_ / "plain.smap").string() + " --trajectory " +
                                           (*dir_ / "plain.csv").string());
  ASSERT_EQ(plain.status, 0) << plain.out;
  EXPECT_NE(defaults.out.find("(covariance window 32); map: bki with the tiled engine"),
            std::string::npos)
      << defaults.out;
  EXPECT_NE(plain.out.find("(covariance window 1); map: bki with the plain engine"),
            std::string::npos)
      << plain.out;

  const auto a = read_trajectory(*dir_ / "defaults.csv");
  const auto b = read_trajectory(*dir_ / "plain.csv");
  ASSERT_GT(a.size(), 4000u);
  ASSERT_EQ(b.size(), a.size());
  // To 1e-6 m per coordinate: the CSV's micrometre digits, each allowed to round either way.
  double worst_axis = 0.0;
  for (const auto& [stamp, p] : a) {
    const auto it = b.find(stamp);
    ASSERT_NE(it, b.end()) << "stamp " << stamp;
    const Pose& q = it->second;
    worst_axis =
        std::max({worst_axis, std::abs(p.x - q.x), std::abs(p.y - q.y), std::abs(p.z - q.z)});
  }
  std::printf("plain vs defaults: %zu poses, largest coordinate difference %.1e m\n", a.size(),
              worst_axis);
  EXPECT_LE(worst_axis, 1e-6 + 1e-12);

  // Tolerance: the tiled engine's kernel polynomial is within 1e-6 sf2 of equation (3) per
  // point (kernel_test), and up to a few thousand points reach a cell over the drive: 1e-4 of
  // the cell's largest evidence, or 1e-3 sf2 (sf2 = 10) in nearly empty cells.
  // The engines allocate blocks differently (the tiled one every block the kernel's cube
  // touches), so a cell only one map holds counts as zero evidence in the other.
  const auto ca = evidence_of(*dir_ / "defaults.smap");
  const auto cb = evidence_of(*dir_ / "plain.smap");
  ASSERT_GT(ca.size(), 10000u);
  double worst = 0.0;
  std::size_t compared = 0;
  const auto check = [&](const auto& from, const auto& to) {
    for (const auto& [key, cell] : from) {
      const auto it = to.find(key);
      const std::vector<float> zeros(cell.size(), 0.0f);
      const std::vector<float>& other = it == to.end() ? zeros : it->second;
      ASSERT_EQ(other.size(), cell.size());
      const float largest = std::max(*std::max_element(cell.begin(), cell.end()),
                                     *std::max_element(other.begin(), other.end()));
      const double tolerance = std::max(1e-4 * largest, 1e-2);
      for (std::size_t k = 0; k < cell.size(); ++k) {
        const double diff = std::abs(cell[k] - other[k]);
        worst = std::max(worst, diff / tolerance);
        ASSERT_LE(diff, tolerance) << "channel " << k << " of a cell with evidence " << largest;
      }
      ++compared;
    }
  };
  check(ca, cb);
  check(cb, ca);
  std::printf("plain vs defaults: %zu cells, worst evidence difference %.2f of the tolerance\n",
              compared / 2, worst);
}

}  // namespace
