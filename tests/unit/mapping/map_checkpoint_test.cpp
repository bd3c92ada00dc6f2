#include "semap/mapping/map_checkpoint.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <thread>
#include <vector>

#include "checkpoint_test_support.hpp"
#include "toy_dataset.hpp"

namespace semap::mapping {
namespace {

namespace fs = std::filesystem;

using testing::expect_same_map;
using testing::scratch_dir;
using testing::SharedDir;

// The robot: inserts the toy scans, checkpointing after every insert, and is killed with
// SIGKILL after `scans` of them (optionally after idling for 0.5 s, polling as the mapping
// stage does while no scans arrive).
[[noreturn]] void map_then_get_killed(const fs::path& log, int scans, bool let_writer_finish) {
  SemanticMap map{MapParams{}};
  MapCheckpoint checkpoint(map, {.path = log, .interval_s = 0.0});
  const auto clouds = testing::toy_scans(1, scans);
  for (const auto& cloud : clouds) checkpoint.after_insert(map.insert(cloud, cloud.origin));
  for (int idle = 0; let_writer_finish && idle < 50; ++idle) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    checkpoint.poll();
  }
  std::raise(SIGKILL);
  std::abort();
}

class KilledRobot : public ::testing::TestWithParam<bool> {};

// kill -9 while mapping: the log holds the map of some number of scans exactly (a commit
// point), losing at most what the writer had not committed; given time, nothing.
TEST_P(KilledRobot, ResumesTheMapOfItsLastCheckpointExactly) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const bool let_writer_finish = GetParam();
  const SharedDir shared(let_writer_finish ? "settled" : "racing");
  const fs::path& dir = shared.path();
  constexpr int kScans = 9;
  EXPECT_EXIT(map_then_get_killed(dir / "map.log", kScans, let_writer_finish),
              ::testing::KilledBySignal(SIGKILL), "");

  SemanticMap resumed{MapParams{}};
  MapCheckpoint checkpoint(resumed, {.path = dir / "map.log", .resume = true});
  const auto stats = checkpoint.stats();
  if (let_writer_finish) {
    EXPECT_EQ(stats.resumed_scans, static_cast<std::uint64_t>(kScans));
  } else {
    // However far the writer got (on a loaded machine, maybe not past its first fsync), the
    // log holds a commit point and the map equals the uninterrupted one there.
    EXPECT_LE(stats.resumed_scans, static_cast<std::uint64_t>(kScans));
  }
  EXPECT_EQ(stats.resumed_blocks, resumed.stats().blocks);

  // The uninterrupted run, stopped at the same scan.
  SemanticMap reference{MapParams{}};
  for (const auto& cloud : testing::toy_scans(1, static_cast<int>(stats.resumed_scans))) {
    reference.insert(cloud, cloud.origin);
  }
  expect_same_map(reference, resumed);
}

INSTANTIATE_TEST_SUITE_P(Timing, KilledRobot, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? "WriterFinished" : "WriterRacing";
                         });

TEST(MapCheckpoint, ANewMapDoesNotAppendToAnOldOne) {
  const fs::path dir = scratch_dir("new_over_old");
  {
    SemanticMap map{MapParams{}};
    MapCheckpoint checkpoint(map, {.path = dir / "map.log"});
    const auto clouds = testing::toy_scans(1, 1);
    checkpoint.after_insert(map.insert(clouds[0], clouds[0].origin));
    checkpoint.flush();
  }
  SemanticMap fresh{MapParams{}};
  try {
    MapCheckpoint checkpoint(fresh, {.path = dir / "map.log"});
    ADD_FAILURE() << "a new map was appended to the old log";
  } catch (const BlockLogError& e) {
    EXPECT_NE(std::string(e.what()).find("holds a map already"), std::string::npos) << e.what();
  }
  // The old map is still there to resume.
  MapCheckpoint resumed(fresh, {.path = dir / "map.log", .resume = true});
  EXPECT_EQ(resumed.stats().resumed_scans, 1u);
  EXPECT_GT(fresh.stats().blocks, 0u);
  fs::remove_all(dir);
}

// A scan of a straight street seen from `x`: ground and two walls within 7 m.
common::LabeledCloud street_scan(float x) {
  common::LabeledCloud cloud;
  cloud.origin = {x, 0.0f, 1.0f};
  for (float dx = -7.0f; dx <= 7.0f; dx += 0.25f) {
    for (float y = -3.9f; y <= 3.9f; y += 0.25f) {
      cloud.points.emplace_back(x + dx, y, 0.0f);
      cloud.labels.push_back(1);
    }
    for (float z = 0.2f; z <= 3.0f; z += 0.25f) {
      for (const float y : {-4.0f, 4.0f}) {
        cloud.points.emplace_back(x + dx, y, z);
        cloud.labels.push_back(y < 0 ? 2 : 3);
      }
    }
  }
  return cloud;
}

// A long drive out and back with a memory radius: the resident blocks stay bounded far below
// the map's size, and the map written out at the end equals the map of the same drive kept
// entirely in memory.
TEST(MapPager, LongDriveStaysBoundedAndLosesNothing) {
  const fs::path dir = scratch_dir("drive");
  MapParams params;
  params.resolution = 0.2f;
  params.max_range = 8.0f;
  params.free_res = 1.0f;
  params.ds_res = 0.2f;
  std::vector<float> stops;
  for (float x = 0.0f; x <= 320.0f; x += 2.5f) stops.push_back(x);
  for (float x = 317.5f; x >= 0.0f; x -= 2.5f) stops.push_back(x);

  SemanticMap reference(params);
  for (const float x : stops) {
    const auto cloud = street_scan(x);
    reference.insert(cloud, cloud.origin);
  }

  SemanticMap map(params);
  std::size_t max_resident = 0;
  MapPager::Stats pager_stats;
  {
    MapCheckpoint checkpoint(map, {.path = dir / "map.log", .interval_s = 0.0, .durable = false});
    // max_range + ell + a block diagonal (1.4 m) < 12 m: every block a scan reaches is in memory.
    MapPager pager(map, checkpoint.log(), 12.0);
    for (const float x : stops) {
      const auto cloud = street_scan(x);
      pager.update(cloud.origin);
      const InsertResult result = map.insert(cloud, cloud.origin);
      pager.after_insert(result);
      checkpoint.after_insert(result);
      max_resident = std::max(max_resident, map.stats().blocks);
    }
    checkpoint.flush();
    pager_stats = pager.stats();
  }
  const std::size_t total = reference.stats().blocks;
  EXPECT_GE(total, 10 * max_resident) << "total " << total << ", max resident " << max_resident;
  EXPECT_GT(pager_stats.evicted, total);  // blocks left behind on the way out and back
  EXPECT_GT(pager_stats.restored, total / 2);
  EXPECT_EQ(pager_stats.late_restores, 0u);

  SemanticMap reloaded(params);
  BlockLog(dir / "map.log", params).load_all(reloaded);
  expect_same_map(reference, reloaded);
  fs::remove_all(dir);
}

// Blocks along the x axis, block i filled with evidence i + 1, for the pager's distance rule.
// With resolution 0.2 and depth 3 a block is 0.8 m, so from the centre of block 0 the centre of
// block i is 0.8 * |i| m away.
MapParams row_params() {
  MapParams params;
  params.resolution = 0.2f;
  params.block_depth = 3;
  return params;
}

std::vector<float> row_evidence(const MapParams& params, int i) {
  return std::vector<float>(static_cast<std::size_t>(params.cells_per_block() * params.num_classes),
                            static_cast<float>(std::abs(i) + 1));
}

void add_row(SemanticMap& map, int first, int last) {
  for (int i = first; i <= last; ++i) {
    map.add_evidence({i, 0, 0}, row_evidence(map.params(), i));
  }
}

bool resident(const SemanticMap& map, int i) { return map.find_block({i, 0, 0}) != nullptr; }

// A block leaves memory when its centre is farther than radius + one block from the robot and
// comes back only within the radius: a block that the robot's jitter moves across the radius
// stays where it is.
TEST(MapPager, EvictsBeyondRadiusPlusABlockAndRestoresWithinTheRadius) {
  const fs::path dir = scratch_dir("hysteresis");
  const MapParams params = row_params();
  SemanticMap map(params);
  add_row(map, -6, 6);
  BlockLog log(dir / "map.log", params, false);
  // Radius 3.9 m: blocks +-5 (centres 4.0 m away) lie between the radius and radius + one block
  // (4.7 m); blocks +-6 (4.8 m) lie beyond it. Their corners nearest the robot are 4.4 m away,
  // so a rule on block origins or corners would keep them.
  MapPager pager(map, log, 3.9);
  const Eigen::Vector3f centre_of_block_0 = params.grid().block_centre({0, 0, 0});
  pager.update(centre_of_block_0);
  EXPECT_TRUE(resident(map, 5));
  EXPECT_TRUE(resident(map, -5));
  EXPECT_FALSE(resident(map, 6));
  EXPECT_FALSE(resident(map, -6));
  EXPECT_EQ(pager.paged_out(), 2u);
  EXPECT_EQ(pager.stats().evicted, 2u);

  // One block towards +x: block 6 is now 4.0 m away, outside the radius: it stays on disk.
  const Eigen::Vector3f one_block = Eigen::Vector3f::UnitX() * params.block_size();
  pager.update(centre_of_block_0 + one_block);
  EXPECT_FALSE(resident(map, 6));
  EXPECT_EQ(pager.stats().restored, 0u);

  // Two blocks towards +x: block 6 is 3.2 m away and comes back with its evidence.
  pager.update(centre_of_block_0 + 2 * one_block);
  ASSERT_TRUE(resident(map, 6));
  EXPECT_EQ(map.find_block({6, 0, 0})->dense(), row_evidence(params, 6));
  EXPECT_EQ(pager.stats().restored, 1u);
  fs::remove_all(dir);
}

// A resumed map that is paged starts empty: the log's blocks count as paged out and come back
// as the robot gets near them, each with the evidence the log holds.
TEST(MapPager, PagesInTheBlocksOfAResumedLog) {
  const fs::path dir = scratch_dir("resume_paged");
  const MapParams params = row_params();
  {
    SemanticMap before(params);
    add_row(before, 0, 9);
    BlockLog log(dir / "map.log", params, false);
    before.for_each_block([&](const common::BlockIndex& index, const Block& block) {
      log.append(index, 1, block.dense(), block.observed_words());
    });
    log.commit(1);
  }
  SemanticMap map(params);
  BlockLog log(dir / "map.log", params, false);
  MapPager pager(map, log, 2.0);
  EXPECT_EQ(pager.paged_out(), 10u);
  pager.update(params.grid().block_centre({0, 0, 0}));
  // Blocks 0, 1 and 2 (centres 0, 0.8 and 1.6 m away) are within the radius.
  EXPECT_EQ(map.stats().blocks, 3u);
  EXPECT_EQ(pager.paged_out(), 7u);
  for (int i = 0; i <= 2; ++i) {
    ASSERT_TRUE(resident(map, i)) << "block " << i;
    EXPECT_EQ(map.find_block({i, 0, 0})->dense(), row_evidence(params, i));
  }
  fs::remove_all(dir);
}

TEST(MapPager, RefusesARadiusThatIsNotPositive) {
  const fs::path dir = scratch_dir("radius");
  const MapParams params = row_params();
  SemanticMap map(params);
  BlockLog log(dir / "map.log", params, false);
  EXPECT_THROW(MapPager(map, log, 0.0), std::invalid_argument);
  EXPECT_THROW(MapPager(map, log, -1.0), std::invalid_argument);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace semap::mapping
