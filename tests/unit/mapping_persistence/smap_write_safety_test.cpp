// A .smap write that fails part-way or whose process is killed mid-write must leave the old file
// byte for byte, and no temporary that outlives the next write.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "semap/mapping/atomic_file.hpp"
#include "semap/mapping/smap_io.hpp"
#include "test_maps.hpp"

namespace semap::mapping {
namespace {

namespace fs = std::filesystem;

std::vector<std::uint8_t> file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Names in `dir` other than `keep`.
std::vector<std::string> others(const fs::path& dir, const std::string& keep) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().filename() != keep) names.push_back(entry.path().filename().string());
  }
  return names;
}

// One robot's layer with `side`^3 blocks, every cell of a block touched: about 1.3 kB a block.
LayeredMap big_map(int side, float value) {
  LayeredMap map(testing::small_logodds_params());
  EvidenceGrid& grid = map.layer(1);
  const int n = map.params().cells_per_side();
  std::vector<float> cell(static_cast<std::size_t>(grid.channels()), 0.0f);
  for (int x = 0; x < side; ++x) {
    for (int y = 0; y < side; ++y) {
      for (int z = 0; z < side; ++z) {
        for (int c = 0; c < n * n * n; ++c) {
          cell[0] = value + static_cast<float>(x - y + z + c) * 0.01f;
          grid.set_cell({x * n + c % n, y * n + (c / n) % n, z * n + c / (n * n)}, cell);
        }
      }
    }
  }
  grid.set_updates(static_cast<std::uint64_t>(value));
  return map;
}

class SmapWrite : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("smap_write_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    path_ = dir_ / "map.smap";
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  fs::path path_;
};

// The child process writes under a file-size limit (SIGXFSZ ignored, so write() fails with
// EFBIG part-way). Exit codes: 0 write_smap threw naming the step, 1 it returned, 2 other.
int write_under_size_limit(const fs::path& path, const LayeredMap& map, rlim_t limit) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit rl{limit, limit};
    if (::setrlimit(RLIMIT_FSIZE, &rl) != 0) ::_exit(3);
    int code = 1;
    try {
      write_smap(path, map);
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      code = what.find("write") != std::string::npos &&
                     what.find(path.filename().string()) != std::string::npos
                 ? 0
                 : 2;
      if (code != 0) std::fprintf(stderr, "unexpected error: %s\n", e.what());
    }
    ::_exit(code);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 100 + WTERMSIG(status);
}

TEST_F(SmapWrite, FailedWriteLeavesOldFileAndNoTemporary) {
  const LayeredMap old_map = testing::random_logodds_map(21, 1, 10);
  write_smap(path_, old_map);
  const auto old_bytes = file_bytes(path_);
  const LayeredMap new_map = big_map(6, 2.0f);
  const std::size_t new_size = encode_smap(new_map).size();
  ASSERT_GT(new_size, old_bytes.size() * 2);
  // Limits below, at and above the old file's size, all below the new one's.
  for (const rlim_t limit : {rlim_t{0}, rlim_t{1}, rlim_t{4096}, rlim_t{old_bytes.size()},
                             rlim_t{new_size / 2}, rlim_t{new_size - 1}}) {
    EXPECT_EQ(write_under_size_limit(path_, new_map, limit), 0) << "limit " << limit;
    EXPECT_EQ(file_bytes(path_), old_bytes) << "old file changed, limit " << limit;
    EXPECT_THAT(others(dir_, "map.smap"), ::testing::IsEmpty()) << "limit " << limit;
  }
  EXPECT_EQ(read_smap(path_).map, old_map);
  // Control: with room for the whole file the same child succeeds.
  EXPECT_EQ(write_under_size_limit(path_, new_map, new_size), 1);
  EXPECT_EQ(read_smap(path_).map, new_map);
}

// A writer rewriting the map in a loop is SIGKILLed at random moments. Each time the file must
// be one of the complete maps; a kill inside write_file_atomically leaves its temporary
// `.map.smap.XXXXXX` (nothing in the dying process can remove it), which the next write_smap
// removes once it is unlocked and stale. The writer loops over the encoded maps, as write_smap
// does after encoding, so that most kills land in the file's write (encoding touches no file).
TEST_F(SmapWrite, KilledWriterLeavesACompleteFile) {
  const LayeredMap old_map = testing::random_logodds_map(22);
  const std::vector<LayeredMap> maps = {big_map(9, 3.0f), big_map(8, 4.0f)};
  std::vector<std::vector<std::uint8_t>> allowed = {encode_smap(old_map)};
  for (const auto& m : maps) allowed.push_back(encode_smap(m));
  // Kills fall anywhere in two writes' time (a write is slow under a sanitizer).
  const auto start = std::chrono::steady_clock::now();
  write_file_atomically(path_, allowed[1]);
  const auto one_write = std::chrono::duration_cast<std::chrono::microseconds>(
      std::chrono::steady_clock::now() - start);
  std::mt19937 rng(20);
  std::uniform_int_distribution<std::int64_t> delay_us(0, 2 * one_write.count());
  int mid_write = 0;
  constexpr int kRounds = 20;
  for (int round = 0; round < kRounds; ++round) {
    write_smap(path_, old_map);
    ASSERT_THAT(others(dir_, "map.smap"), ::testing::IsEmpty()) << "round " << round;
    // The child says when its first write is done, so that the random moment falls in its loop
    // of writes, not in its start-up (slow under a sanitizer on a loaded machine).
    int ready[2];
    ASSERT_EQ(::pipe(ready), 0);
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::close(ready[0]);
      write_file_atomically(path_, allowed[1]);
      const char byte = 1;
      if (::write(ready[1], &byte, 1) != 1) ::_exit(3);
      for (std::size_t i = 1;; ++i) write_file_atomically(path_, allowed[1 + i % maps.size()]);
    }
    ASSERT_GT(pid, 0);
    ::close(ready[1]);
    char byte = 0;
    const ssize_t started = ::read(ready[0], &byte, 1);
    ::close(ready[0]);
    ASSERT_EQ(started, 1) << "round " << round << ": the writer died before its first write";
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "round " << round;

    const auto now = file_bytes(path_);
    EXPECT_THAT(allowed, ::testing::Contains(now))
        << "round " << round << ": " << now.size() << " bytes, not any complete map";
    const auto left = others(dir_, "map.smap");
    ASSERT_LE(left.size(), 1u) << "round " << round;
    if (left.empty()) continue;
    ++mid_write;
    EXPECT_THAT(left[0], ::testing::StartsWith(".map.smap.")) << "round " << round;
    // Young: kept (it could be a live writer between mkstemp and flock).
    EXPECT_EQ(remove_stale_temporaries(path_), 0u);
    const fs::path temp = dir_ / left[0];
    fs::last_write_time(temp, fs::file_time_type::clock::now() - std::chrono::minutes(5));
    write_smap(path_, old_map);
    EXPECT_THAT(others(dir_, "map.smap"), ::testing::IsEmpty())
        << "round " << round << ": the next write left the dead writer's temporary";
    EXPECT_EQ(file_bytes(path_), allowed[0]);
  }
  std::printf("%d of %d kills landed inside a write (%.1f ms a write)\n", mid_write, kRounds,
              1e-3 * static_cast<double>(one_write.count()));
  EXPECT_GT(mid_write, 0) << "no kill hit a write: the test exercised nothing";
}

// A temporary that a live writer holds locked is never removed, however old.
TEST_F(SmapWrite, LockedTemporaryIsKept) {
  const fs::path temp = dir_ / ".map.smap.AbC123";
  std::ofstream(temp) << "partial";
  fs::last_write_time(temp, fs::file_time_type::clock::now() - std::chrono::minutes(5));
  const int fd = ::open(temp.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  write_smap(path_, testing::random_logodds_map(23));
  EXPECT_TRUE(fs::exists(temp));
  ::close(fd);
  // Other names that merely look similar are never touched.
  const fs::path other = dir_ / ".map.smap.bak";
  std::ofstream(other) << "x";
  fs::last_write_time(other, fs::file_time_type::clock::now() - std::chrono::minutes(5));
  EXPECT_EQ(remove_stale_temporaries(path_), 1u);
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_TRUE(fs::exists(other));
}

}  // namespace
}  // namespace semap::mapping
