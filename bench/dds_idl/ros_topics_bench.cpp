// ros_topics_bench: the ROS-readable map topics of issue 17 on a map of a million cells (the
// synthetic LiDAR street of bench/mapping), to a reader in another process over loopback:
//  - building and publishing map_cloud (every occupied cell) and the whole-map costmap, each
//    timed on the publishing thread, against publishing the same map as map_blocks;
//  - at 10 Hz rounds of one camera-sized insert each, the latency from the round's stamp to
//    receipt of map_cloud_updates, costmap_updates and (baseline) map_blocks: p50 / p99 / max.
//   ros_topics_bench [repetitions [seconds]]   (default 10 and 10)
// The reader is this binary again (`--reader DOMAIN NS`). CYCLONEDDS_URI defaults to the
// loopback XML of the source tree, so nothing leaves 127.0.0.1.
#include <signal.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "child_pipe.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/dds_idl/reader.hpp"
#include "semap/dds_idl/topic_names.hpp"
#include "semap/onboard/costmap_output.hpp"
#include "semap/onboard/mapping_stage.hpp"
#include "synthetic_lidar.hpp"

namespace sd = semap::dds_idl;
namespace sm = semap::mapping;
using semap::common::Stamp;
using Clock = std::chrono::steady_clock;
using semap::bench::Pipe;

namespace {

constexpr std::size_t kTargetCells = 1'000'000;
constexpr int kClasses = 20;

sm::MapParams street_params() {
  sm::MapParams p;
  p.resolution = 0.1f;
  p.num_classes = kClasses;
  p.block_depth = 3;
  p.ell = 0.2f;
  p.free_res = 4.0f;
  p.ds_res = 0.2f;
  p.max_range = 25.0f;
  return p;
}

sm::CostmapParams whole_map_costs() {
  sm::CostmapParams p;  // width_m 0: the whole map
  p.class_cost.assign(kClasses, 100);
  p.class_cost[0] = p.class_cost[1] = p.class_cost[2] = 0;
  p.class_cost[3] = 40;
  p.class_cost[4] = 70;
  p.ground_class.assign(kClasses, false);
  p.ground_class[1] = p.ground_class[2] = true;
  return p;
}

// The map read as the mapping stage gives it to the publisher (one thread here: no lock).
class MapView : public sd::BlockSource, public semap::onboard::CostmapSource {
 public:
  explicit MapView(const sm::SemanticMap& map) : map_(map) {}
  void for_each_block(
      const std::function<void(const semap::common::BlockIndex&)>& f) const override {
    map_.for_each_block(
        [&](const semap::common::BlockIndex& index, const sm::Block&) { f(index); });
  }
  bool read(const semap::common::BlockIndex& index, sd::BlockSnapshot& out) const override {
    return read_block(index, true, out);
  }
  bool read_cells(const semap::common::BlockIndex& index, sd::BlockSnapshot& out) const override {
    return read_block(index, false, out);
  }
  sm::Costmap build_costmap(const sm::CostmapParams& p,
                            const Eigen::Vector2d& centre) const override {
    return sm::build_costmap(map_, p, centre);
  }
  sm::CostmapUpdate update_costmap(
      sm::Costmap& costmap, const sm::CostmapParams& p,
      std::span<const semap::common::BlockIndex> changed) const override {
    return sm::update_costmap(costmap, map_, p, changed);
  }

 private:
  bool read_block(const semap::common::BlockIndex& index, bool with_evidence,
                  sd::BlockSnapshot& out) const {
    const sm::Block* block = map_.find_block(index);
    if (block == nullptr) return false;
    semap::onboard::to_snapshot(map_, index, *block, 1, with_evidence, out);
    return true;
  }
  const sm::SemanticMap& map_;
};

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

std::string self_path() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw std::runtime_error("readlink /proc/self/exe");
  return std::string(buf, static_cast<std::size_t>(n));
}

// ---- reader side (child process) ----

// Milliseconds from a header stamp (ROS time) to now.
double age_ms(const sd::msg::Time& t) {
  const double now =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  return 1e3 * (now - (static_cast<double>(t.sec_) + 1e-9 * t.nanosec_));
}

// Prints "<topic> <age ms> <size>" per message until stdin closes.
int run_reader(int domain, const std::string& ns) {
  sd::Participant p(domain);
  using sd::SemapTopic;
  const auto reader_of = [&](SemapTopic t, auto type) {
    using T = decltype(type);
    auto topic = std::make_unique<sd::Topic<T>>(p, sd::topic_name(ns, t), sd::topic_qos(t));
    auto reader = std::make_unique<sd::Reader<T>>(p, *topic, sd::topic_qos(t));
    return std::make_pair(std::move(topic), std::move(reader));
  };
  auto cloud = reader_of(SemapTopic::kMapCloud, sd::msg::PointCloud2{});
  auto cloud_updates = reader_of(SemapTopic::kMapCloudUpdates, sd::msg::PointCloud2{});
  auto grid = reader_of(SemapTopic::kCostmap, sd::msg::OccupancyGrid{});
  auto grid_updates = reader_of(SemapTopic::kCostmapUpdates, sd::msg::OccupancyGridUpdate{});
  auto blocks = reader_of(SemapTopic::kMapBlocks, sd::msg::SemanticMapBlock{});
  std::cout << "ready " << getpid() << std::endl;
  for (;;) {
    std::this_thread::sleep_for(std::chrono::microseconds(500));
    cloud.second->take_each([](const sd::msg::PointCloud2& m, const dds_sample_info_t&) {
      std::cout << "map_cloud " << age_ms(m.header_.stamp_) << ' ' << m.width_ << std::endl;
    });
    cloud_updates.second->take_each([](const sd::msg::PointCloud2& m, const dds_sample_info_t&) {
      std::cout << "map_cloud_updates " << age_ms(m.header_.stamp_) << ' ' << m.width_ << std::endl;
    });
    grid.second->take_each([](const sd::msg::OccupancyGrid& m, const dds_sample_info_t&) {
      std::cout << "costmap " << age_ms(m.header_.stamp_) << ' ' << m.data_._length << std::endl;
    });
    grid_updates.second->take_each(
        [](const sd::msg::OccupancyGridUpdate& m, const dds_sample_info_t&) {
          std::cout << "costmap_updates " << age_ms(m.header_.stamp_) << ' ' << m.data_._length
                    << std::endl;
        });
    blocks.second->take_each([](const sd::msg::SemanticMapBlock& m, const dds_sample_info_t&) {
      std::cout << "map_blocks " << age_ms(m.header_.stamp_) << " 1" << std::endl;
    });
  }
}

// ---- publisher side ----

// The reader's lines, collected on a thread of their own: ages per topic.
class ReaderLog {
 public:
  explicit ReaderLog(const std::string& cmd) : pipe_(cmd) {
    std::string l;
    while (pipe_.line(l) && l.rfind("ready ", 0) != 0) {
    }
    pid_ = std::atoi(l.c_str() + 6);
    if (pid_ <= 0) throw std::runtime_error("the reader did not start");
    thread_ = std::thread([this] {
      std::string line;
      while (pipe_.line(line)) {
        std::istringstream s(line);
        std::string topic;
        double age = 0, size = 0;
        s >> topic >> age >> size;
        std::lock_guard lock(mutex_);
        ages_[topic].push_back(age);
      }
    });
  }
  ~ReaderLog() {
    kill(pid_, SIGTERM);
    thread_.join();
  }
  std::vector<double> take(const std::string& topic) {
    std::lock_guard lock(mutex_);
    return std::exchange(ages_[topic], {});
  }
  // Waits until `topic` has at least `n` messages (or 10 s).
  void wait_for(const std::string& topic, std::size_t n) {
    const auto deadline = Clock::now() + std::chrono::seconds(10);
    while (Clock::now() < deadline) {
      {
        std::lock_guard lock(mutex_);
        if (ages_[topic].size() >= n) return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }

 private:
  Pipe pipe_;
  pid_t pid_ = 0;
  std::thread thread_;
  std::mutex mutex_;
  std::map<std::string, std::vector<double>> ages_;
};

void print_times(const char* what, const std::vector<double>& ms, const std::string& extra) {
  std::printf("%-44s median %7.1f ms  max %7.1f ms  %s\n", what, percentile(ms, 0.5),
              percentile(ms, 1.0), extra.c_str());
}

void print_latency(const char* what, const std::vector<double>& ms) {
  std::printf("%-44s p50 %6.2f ms  p99 %6.2f ms  max %6.2f ms  (%zu messages)\n", what,
              percentile(ms, 0.5), percentile(ms, 0.99), percentile(ms, 1.0), ms.size());
}

int run(int repetitions, double seconds) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  std::random_device rd;
  const int domain = 1 + static_cast<int>(rd() % 200);
  const std::string ns = "ros_bench";

  std::printf("ros_topics_bench: domain %d, CYCLONEDDS_URI=%s, %d repetitions, %.0f s at 10 Hz\n",
              domain, std::getenv("CYCLONEDDS_URI"), repetitions, seconds);
  semap::bench::SyntheticLidar lidar;
  sm::SemanticMap map(street_params());
  int next_scan = 0;
  Eigen::Vector2d robot = Eigen::Vector2d::Zero();
  // A scan, or with `radius` > 0 a camera-sized part of it: within radius, and 45 degrees
  // either side of the direction the sensor moved since the last scan.
  const auto insert_next = [&](float radius) {
    auto cloud = lidar.scan(next_scan++);
    const Eigen::Vector2f heading = (cloud.origin.head<2>() - robot.cast<float>()).normalized();
    robot = cloud.origin.head<2>().cast<double>();
    std::size_t kept = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Eigen::Vector3f ray = cloud.points[i] - cloud.origin;
      if (radius > 0.0f &&
          (ray.norm() > radius || ray.head<2>().normalized().dot(heading) < std::sqrt(0.5f))) {
        continue;
      }
      cloud.points[kept] = cloud.points[i];
      cloud.labels[kept++] = cloud.labels[i];
    }
    cloud.points.resize(kept);
    cloud.labels.resize(kept);
    return map.insert(cloud, cloud.origin);
  };
  while (map.stats().cells < kTargetCells) insert_next(0.0f);
  const MapView view(map);

  sd::Participant participant(domain);
  sd::MapDescription description;
  description.resolution = street_params().resolution;
  description.block_cells = static_cast<std::uint16_t>(street_params().cells_per_side());
  description.num_classes = kClasses;
  // blocks_hz 20: every 10 Hz round is due; cloud_hz only enables map_cloud_updates (the bench
  // writes the cloud itself).
  sd::MapPublisher publisher(participant, {ns, "map", 20.0, 1e-3}, description, view);
  semap::onboard::CostmapConfig costmap{whole_map_costs(), 10.0};
  ReaderLog reader(self_path() + " --reader " + std::to_string(domain) + " " + ns);
  while (publisher.matched_readers() == 0)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));

  // Whole map: map_blocks (baseline), map_cloud, the whole-map costmap.
  std::vector<double> blocks_ms, cloud_ms, costmap_ms;
  std::size_t blocks = 0, grid_cells = 0;
  for (int r = 0; r < repetitions; ++r) {
    view.for_each_block([&](const semap::common::BlockIndex& index) { publisher.changed(index); });
    auto t = Clock::now();
    blocks = publisher.publish_changed(Stamp::now());
    blocks_ms.push_back(ms_since(t));
    reader.wait_for("map_blocks", blocks);
    t = Clock::now();
    publisher.publish_cloud(Stamp::now());
    cloud_ms.push_back(ms_since(t));
    reader.wait_for("map_cloud", 1);
    // A new output each time: its first round builds and writes the whole grid.
    semap::onboard::CostmapOutput output(participant, ns, "map", costmap, view);
    t = Clock::now();
    output.spin_once(Stamp::now(), robot);
    costmap_ms.push_back(ms_since(t));
    reader.wait_for("costmap", 1);
    reader.take("map_blocks");
    reader.take("map_cloud");
    reader.take("costmap");
  }
  const auto stats = map.stats();
  std::size_t occupied = 0;
  {
    sd::BlockSnapshot block;
    view.for_each_block([&](const semap::common::BlockIndex& index) {
      view.read(index, block);
      occupied += static_cast<std::size_t>(
          std::count(block.state.begin(), block.state.end(), semap::common::CellState::kOccupied));
    });
    grid_cells = static_cast<std::size_t>(view.build_costmap(costmap.params, robot).data.size());
  }
  std::printf("map: %zu cells in %zu blocks, %zu observed, %zu occupied; load %.2f\n", stats.cells,
              blocks, stats.observed_cells, occupied, [] {
                double l[1] = {0};
                return getloadavg(l, 1) == 1 ? l[0] : -1.0;
              }());
  print_times("map_blocks, whole map (baseline)", blocks_ms,
              std::to_string(blocks) + " blocks with evidence");
  print_times(
      "map_cloud, build + publish", cloud_ms,
      std::to_string(occupied) + " points, " + std::to_string(occupied * 24 / 1000) + " kB");
  print_times(
      "costmap, whole map, build + publish", costmap_ms,
      std::to_string(grid_cells) + " cells at " + std::to_string(costmap.params.resolution) + " m");

  // 10 Hz rounds: one camera-sized insert each, then the publisher's round.
  semap::onboard::CostmapConfig window{whole_map_costs(), 20.0};  // every round due
  window.params.width_m = window.params.height_m = 40.0;
  semap::onboard::CostmapOutput output(participant, ns, "map", window, view);
  output.spin_once(Stamp::now(), robot);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  for (const char* topic : {"costmap", "costmap_updates", "map_cloud_updates", "map_blocks"}) {
    reader.take(topic);  // the whole-map rounds'
  }
  std::vector<double> round_ms;
  const auto start = Clock::now();
  auto next = start;
  const std::uint64_t update_points0 = publisher.counters().cloud_update_points;
  const std::uint64_t blocks0 = publisher.counters().blocks_written;
  int rounds = 0;
  while (Clock::now() - start < std::chrono::duration<double>(seconds)) {
    const auto result = insert_next(8.0f);
    for (const auto& index : result.updated_blocks) {
      publisher.changed(index);
      output.changed(index);
    }
    const auto t = Clock::now();
    const Stamp now = Stamp::now();
    publisher.spin_updates(now);  // in DdsOutputs' order
    output.spin_once(now, robot);
    publisher.spin_once(now);
    round_ms.push_back(ms_since(t));
    ++rounds;
    next += std::chrono::milliseconds(100);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  std::printf(
      "%d rounds at 10 Hz, %.0f blocks and %.0f map_cloud_updates points a round; publisher round "
      "%s\n",
      rounds, static_cast<double>(publisher.counters().blocks_written - blocks0) / rounds,
      static_cast<double>(publisher.counters().cloud_update_points - update_points0) / rounds,
      (std::to_string(percentile(round_ms, 0.5)).substr(0, 5) + " ms median").c_str());
  print_latency("map_cloud_updates latency", reader.take("map_cloud_updates"));
  print_latency("costmap_updates latency (40 m window)", reader.take("costmap_updates"));
  print_latency("costmap latency (40 m window)", reader.take("costmap"));
  print_latency("map_blocks latency (baseline, per block)", reader.take("map_blocks"));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    setenv("CYCLONEDDS_URI", "file://" SEMAP_DDS_LOOPBACK_XML, 0);
    if (argc == 4 && std::strcmp(argv[1], "--reader") == 0) {
      return run_reader(std::atoi(argv[2]), argv[3]);
    }
    const int repetitions = argc > 1 ? std::atoi(argv[1]) : 10;
    const double seconds = argc > 2 ? std::atof(argv[2]) : 10.0;
    return run(std::max(1, repetitions), std::max(1.0, seconds));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ros_topics_bench: %s\n", e.what());
    return 1;
  }
}
