// The map checkpoint on a disk that fills: a file-size limit (RLIMIT_FSIZE, SIGXFSZ ignored as
// semap-onboard ignores it) makes the log's writes fail with EFBIG part-way through a record,
// as a full disk fails them with ENOSPC. The robot's process must live on, count the failures,
// keep the last complete checkpoint loadable and write again once there is room.
//
// The limit is set in a child process of its own: a "threadsafe" death test re-executes this
// binary and runs only the child's part, so no TBB worker of another test is forked and the
// limit never reaches the test runner.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "checkpoint_test_support.hpp"
#include "semap/mapping/map_checkpoint.hpp"
#include "toy_dataset.hpp"

namespace semap::mapping {
namespace {

namespace fs = std::filesystem;

using testing::expect_same_map;
using testing::SharedDir;

constexpr int kBefore = 3;  // scans checkpointed before the limit
constexpr int kDuring = 3;  // scans mapped while every checkpoint fails
constexpr int kAfter = 1;   // scans mapped once the limit is raised again

// The child's checks: a failed one names itself on stderr and exits with its code, so the
// parent's EXPECT_EXIT shows which.
void require(bool ok, int code, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "child check %d failed: %s\n", code, what.c_str());
  std::fflush(stderr);
  ::_exit(code);
}

void set_file_size_limit(rlim_t soft) {
  rlimit rl{};
  ::getrlimit(RLIMIT_FSIZE, &rl);
  rl.rlim_cur = soft;  // the hard limit stays, so the soft one can be raised again
  require(::setrlimit(RLIMIT_FSIZE, &rl) == 0, 2, "setrlimit: " + std::string(strerror(errno)));
}

std::vector<std::uint8_t> file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// The robot's mapping thread with its checkpoint writer, on a disk that fills after kBefore
// scans and, with `room_returns`, has room again for the last kAfter scans.
[[noreturn]] void map_while_the_disk_fills(const fs::path& log_path, bool room_returns) {
  ::signal(SIGXFSZ, SIG_IGN);
  SemanticMap map{MapParams{}};
  MapCheckpoint checkpoint(map, {.path = log_path, .interval_s = 0.0});
  const auto clouds = testing::toy_scans(1, kBefore + kDuring + kAfter);
  const auto map_scan = [&](int i) {
    checkpoint.after_insert(map.insert(clouds[static_cast<std::size_t>(i)],
                                       clouds[static_cast<std::size_t>(i)].origin));
  };
  for (int i = 0; i < kBefore; ++i) map_scan(i);
  checkpoint.flush();
  require(checkpoint.stats().write_failures == 0, 3, "failures before the limit");
  require(checkpoint.stats().committed_scans == kBefore, 4, "first checkpoint not committed");

  // Room for 4 kB more: the next checkpoint stops part-way through a record.
  const auto limit = fs::file_size(log_path) + 4096;
  set_file_size_limit(limit);
  for (int i = kBefore; i < kBefore + kDuring; ++i) map_scan(i);
  checkpoint.flush();  // the stop of a robot: nothing may be thrown here either
  const auto full = checkpoint.stats();
  require(full.write_failures >= 2, 5, "failures counted: " + std::to_string(full.write_failures));
  require(full.failing, 6, "not reported as failing");
  require(full.committed_scans == kBefore, 7, "commit after a failed write");
  require(full.last_error.find(log_path.string()) != std::string::npos &&
              full.last_error.find(std::strerror(EFBIG)) != std::string::npos,
          8, "error does not name the file and EFBIG: " + full.last_error);
  require(map.scans() == static_cast<std::size_t>(kBefore + kDuring), 9, "mapping stopped");
  // On disk: whole records only (the failed write was cut off), the last commit kBefore's.
  const auto bytes = file_bytes(log_path);
  require(bytes.size() <= limit, 10, "log beyond the limit");
  const BlockLogScan scan = scan_block_log(bytes, map.params(), log_path.string());
  require(scan.damage.empty(), 11, "torn tail left: " + scan.damage);
  require(scan.committed_scans == kBefore, 12, "on-disk commit " + std::to_string(scan.commits));
  if (!room_returns) ::_exit(0);

  set_file_size_limit(RLIM_INFINITY);
  for (int i = kBefore + kDuring; i < kBefore + kDuring + kAfter; ++i) map_scan(i);
  checkpoint.flush();
  const auto after = checkpoint.stats();
  require(!after.failing, 13, "still failing with room: " + after.last_error);
  require(after.committed_scans == kBefore + kDuring + kAfter, 14, "no commit with room");
  require(after.write_failures == full.write_failures, 15, "failures with room");
  ::_exit(0);
}

// The uninterrupted map of the first `scans` toy scans.
SemanticMap reference_map(int scans) {
  SemanticMap map{MapParams{}};
  for (const auto& cloud : testing::toy_scans(1, scans)) map.insert(cloud, cloud.origin);
  return map;
}

TEST(CheckpointOnAFullDisk, FailsWithoutThrowingAndTheLastCheckpointReloadsIntact) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const SharedDir shared("full_disk_stays_full");
  const fs::path log = shared.path() / "map.log";
  EXPECT_EXIT(map_while_the_disk_fills(log, false), ::testing::ExitedWithCode(0), "");

  SemanticMap resumed{MapParams{}};
  const MapCheckpoint checkpoint(resumed, {.path = log, .resume = true});
  EXPECT_EQ(checkpoint.stats().resumed_scans, static_cast<std::uint64_t>(kBefore));
  EXPECT_EQ(checkpoint.damage(), "");  // the failed write left no torn record
  expect_same_map(reference_map(kBefore), resumed);
}

TEST(CheckpointOnAFullDisk, WritingResumesWithRoomAndTheReloadHasEveryNewBlock) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const SharedDir shared("full_disk_room_returns");
  const fs::path log = shared.path() / "map.log";
  EXPECT_EXIT(map_while_the_disk_fills(log, true), ::testing::ExitedWithCode(0), "");

  // Every block changed while the disk was full is in the log, not only the last scan's.
  SemanticMap resumed{MapParams{}};
  const MapCheckpoint checkpoint(resumed, {.path = log, .resume = true});
  EXPECT_EQ(checkpoint.stats().resumed_scans,
            static_cast<std::uint64_t>(kBefore + kDuring + kAfter));
  expect_same_map(reference_map(kBefore + kDuring + kAfter), resumed);
}

// The pager on a full disk: a block the log cannot take stays in memory (the map grows past its
// radius instead of losing evidence) and leaves once the log has room.
[[noreturn]] void page_while_the_disk_is_full(const fs::path& log_path) {
  ::signal(SIGXFSZ, SIG_IGN);
  MapParams params;
  params.resolution = 0.2f;
  params.block_depth = 3;  // 0.8 m blocks
  SemanticMap map(params);
  const std::vector<float> evidence(
      static_cast<std::size_t>(params.cells_per_block() * params.num_classes), 1.0f);
  for (int i = 0; i <= 20; ++i) map.add_evidence({i, 0, 0}, evidence);
  BlockLog log(log_path, params, false);
  MapPager pager(map, log, 2.0);
  set_file_size_limit(fs::file_size(log_path) + 100);  // less than one block record
  pager.update({0.4f, 0.4f, 0.4f});
  require(map.stats().blocks == 21, 20, "blocks left memory without reaching the log");
  require(pager.stats().write_failures >= 1 && pager.stats().failing, 21, "failure not counted");
  require(pager.stats().last_error.find(std::strerror(EFBIG)) != std::string::npos, 22,
          "error: " + pager.stats().last_error);
  set_file_size_limit(RLIM_INFINITY);
  pager.update({0.4f, 0.4f, 0.4f});
  require(!pager.stats().failing, 23, "still failing with room");
  require(map.stats().blocks < 21 && log.blocks().size() + map.stats().blocks == 21, 24,
          "blocks not paged out with room");
  ::_exit(0);
}

TEST(CheckpointOnAFullDisk, ThePagerKeepsBlocksInMemoryUntilTheLogTakesThem) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const SharedDir shared("full_disk_pager");
  EXPECT_EXIT(page_while_the_disk_is_full(shared.path() / "map.log"), ::testing::ExitedWithCode(0),
              "");
}

}  // namespace
}  // namespace semap::mapping
