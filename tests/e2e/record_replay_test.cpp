// semap-onboard --record on the simulated rig, then the recording replayed (rig.kind: replay):
// as fast as possible it must give the recorded run's trajectory (within 1 mm) and map (the same
// occupied cells and classes); at recorded pace, with the GNSS bytes through a pty to the real
// driver, nearly the same; a damaged recording plays up to the damage and names it. The plain
// maths (map.engine: plain, estimator.covariance_window: 1) replayed as fast as possible gives
// the defaults' trajectory and map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "semap/common/map_grid.hpp"
#include "semap/drivers/stream_log.hpp"
#include "semap/firmware_bridge/candump_reader.hpp"
#include "semap/map_io/map_export.hpp"
#include "semap/mapping/smap_io.hpp"
#include "support/cli_run.hpp"

namespace {

namespace fs = std::filesystem;
using semap::test_support::run_cli;

const std::string kOnboard = SEMAP_ONBOARD;

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
    live_ = new semap::test_support::CliResult(run_cli(
        kOnboard, "--config " + (*dir_ / "live.yaml").string() + " --record " +
                      (*dir_ / "rec").string() + " --trajectory " + (*dir_ / "live.csv").string()));
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
  static fs::path rec() { return *dir_ / "rec"; }

  static fs::path* dir_;
  static semap::test_support::CliResult* live_;
};
fs::path* RecordReplay::dir_ = nullptr;
semap::test_support::CliResult* RecordReplay::live_ = nullptr;

TEST_F(RecordReplay, TheRecordingHoldsEveryStream) {
  const std::string& out = live_->out;
  // The IMU as a candump -L log, each frame of the semap protocol under the rig's name.
  std::ifstream imu(rec() / "imu.log");
  semap::firmware_bridge::CandumpReader candump(imu, "imu.log");
  long long frames = 0;
  while (const auto r = candump.next()) {
    EXPECT_STREQ(r->interface, "sim");
    ++frames;
  }
  EXPECT_EQ(candump.error(), "");
  EXPECT_EQ(frames, figure(out, "recording        : " + rec().string() + ": "));
  // can-utils reads it as its own: log2asc converts every line.
  if (fs::exists("/usr/bin/log2asc")) {
    const auto asc = run_cli("/usr/bin/log2asc", "-I " + (rec() / "imu.log").string() + " sim");
    ASSERT_EQ(asc.status, 0) << asc.out.substr(0, 500);
    long long rx = 0;
    for (std::size_t at = asc.out.find(" Rx "); at != std::string::npos;
         at = asc.out.find(" Rx ", at + 1)) {
      ++rx;
    }
    EXPECT_EQ(rx, frames);
  }
  // 3 frames per sample of the semap profile.
  EXPECT_EQ(frames, 3 * figure(out, "estimation       : ")) << out;

  // The GNSS port's bytes, all the driver read.
  std::ifstream gnss_file(rec() / "gnss.log", std::ios::binary);
  semap::drivers::StreamLogReader gnss(gnss_file, "gnss.log",
                                       semap::drivers::StreamLogKind::kBytes);
  long long bytes = 0;
  while (const auto chunk = gnss.next_bytes()) bytes += static_cast<long long>(chunk->bytes.size());
  EXPECT_EQ(gnss.error(), "");
  EXPECT_EQ(bytes, figure(out, "fixes, ")) << out;

  // Camera frames, every one the perception stage took.
  for (const char* name : {"colour.log", "depth.log"}) {
    std::ifstream file(rec() / name, std::ios::binary);
    semap::drivers::StreamLogReader log(file, name, semap::drivers::StreamLogKind::kFrames);
    long long n = 0;
    while (const auto f = log.next_frame()) {
      EXPECT_EQ(f->width, 320u);
      ++n;
    }
    EXPECT_EQ(log.error(), "");
    EXPECT_EQ(n, figure(out, "perception       : ")) << name;
  }
  EXPECT_EQ(slurp(rec() / "config.yaml"), slurp(*dir_ / "live.yaml"));
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
// filter sees GNSS a few hundred microseconds off the recording's stamps.
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
  std::printf(
      "recorded pace vs the recorded run: position difference median %.2f mm, max %.1f mm\n",
      1e3 * median, 1e3 * d.back());
  EXPECT_LE(median, 0.01);
  EXPECT_LE(d.back(), 0.5);
  const double shared =
      shared_fraction(cells_of(*dir_ / "live.smap"), cells_of(*dir_ / "paced.smap"));
  std::printf("occupied cells of the recorded run's map found with the same class: %.3f\n", shared);
  EXPECT_GE(shared, 0.9);
}

TEST_F(RecordReplay, ADamagedRecordingPlaysUpToTheDamage) {
  const fs::path damaged = *dir_ / "damaged";
  fs::copy(rec(), damaged);
  // The colour log cut in the middle of a late frame (a crash mid-write).
  const auto colour = damaged / "colour.log";
  fs::resize_file(colour, fs::file_size(colour) * 9 / 10);
  const auto r = run_cli(kOnboard, "--replay " + damaged.string() + " --pace fast --save " +
                                       (*dir_ / "damaged.smap").string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("damaged: " + colour.string() + ": record "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": data: truncated"), std::string::npos) << r.out;
  // The other streams go on to their ends.
  EXPECT_EQ(figure(r.out, "estimation       : "), figure(live_->out, "estimation       : "));
  EXPECT_EQ(figure(r.out, "GNSS fixes ("), figure(live_->out, "GNSS fixes ("));
  const long long colour_frames = figure(r.out, "GNSS reads, ");
  EXPECT_GT(colour_frames, 0);
  EXPECT_LT(colour_frames,
            figure(line_of(live_->out, "perception       : "), "perception       : "));

  // A line of the CAN log that is not candump -L: named by file and line.
  fs::copy(rec() / "colour.log", colour, fs::copy_options::overwrite_existing);
  std::string imu = slurp(damaged / "imu.log");
  const auto line_1000 = [&] {
    std::size_t at = 0;
    for (int i = 0; i < 999; ++i) at = imu.find('\n', at) + 1;
    return at;
  }();
  imu.insert(line_1000, "(12.500000) sim 123#XYZ\n");
  std::ofstream(damaged / "imu.log") << imu;
  const auto bad = run_cli(kOnboard, "--replay " + damaged.string() + " --pace fast --save " +
                                         (*dir_ / "damaged.smap").string());
  // The 999 frames before the bad line: 333 samples of 3 frames each.
  EXPECT_EQ(figure(line_of(bad.out, "replay           : "), "error frames), "), 333) << bad.out;
  EXPECT_NE(bad.out.find((damaged / "imu.log").string() + ":1000: data"), std::string::npos)
      << bad.out;
}

// The definitions the fast paths are tested against, selected by configuration, on the recorded
// drive: the S-BKI update as the paper writes it (map.engine: plain) and the per-step covariance
// propagation (estimator.covariance_window: 1), against the defaults (tiled engine, 32-step
// window), both replayed as fast as possible.
TEST_F(RecordReplay, ThePlainMathsGiveTheDefaultsRun) {
  std::string config = slurp(rec() / "config.yaml");
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
