// A recording on a disk that fills: a file-size limit (RLIMIT_FSIZE, SIGXFSZ ignored as
// semap-onboard ignores it) makes writes fail part-way through a batch, as ENOSPC does. The log
// must keep only whole records, count the lost ones with the errno text, and record again once
// there is room. The limit is set in a forked child (this binary runs no threads between
// tests), which reports each failed check by its exit code.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "semap/drivers/stream_log.hpp"

namespace semap::drivers {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kChunk = 1000;  // bytes per record
constexpr int kBefore = 100;          // records written before the limit
constexpr rlim_t kLimit = 200 * 1024;

std::vector<std::uint8_t> chunk(int i) {
  return std::vector<std::uint8_t>(kChunk, static_cast<std::uint8_t>(i));
}

void require(bool ok, int code, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "child check %d failed: %s\n", code, what.c_str());
  ::_exit(code);
}

void set_limit(rlim_t soft) {
  rlimit rl{};
  ::getrlimit(RLIMIT_FSIZE, &rl);
  rl.rlim_cur = soft;
  require(::setrlimit(RLIMIT_FSIZE, &rl) == 0, 2, std::strerror(errno));
}

// Records 0..kBefore-1 fit; then the limit stops the log part-way through a batch; after the
// limit is raised and the retry interval has passed, record 1000 goes in.
[[noreturn]] void record_while_the_disk_fills(const fs::path& path) {
  ::signal(SIGXFSZ, SIG_IGN);
  StreamLogWriter log(path, StreamLogKind::kBytes, std::chrono::milliseconds(20));
  for (int i = 0; i < kBefore; ++i) log.write_bytes(common::Stamp(i), chunk(i));
  require(log.flush() && log.records() == kBefore, 3, "records before the limit");
  set_limit(kLimit);
  int lost = 0;
  for (int i = kBefore; i < kBefore + 400; ++i)
    lost += log.write_bytes(common::Stamp(i), chunk(i)) ? 0 : 1;
  log.flush();
  const AppendFile& f = log.file();
  require(!log.ok() && f.failing(), 4, "not failing");
  require(f.lost() >= 200 && f.failures() >= 1, 5, "lost " + std::to_string(f.lost()));
  require(f.error() == path.string() + ": write: " + std::strerror(EFBIG), 6, f.error());
  require(fs::file_size(path) == f.bytes() && f.bytes() <= kLimit, 7, "torn or past the limit");
  set_limit(RLIM_INFINITY);
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  require(log.write_bytes(common::Stamp(1000), chunk(1000 % 256)) && log.flush(), 8,
          "no record with room: " + f.error());
  require(log.ok(), 9, "still failing with room");
  ::_exit(0);
}

TEST(StreamLogOnAFullDisk, KeepsWholeRecordsCountsTheLostAndRecordsAgainWithRoom) {
  const fs::path dir =
      fs::temp_directory_path() / ("stream_log_full_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / "gnss.log";
  const pid_t pid = ::fork();
  if (pid == 0) record_while_the_disk_fills(path);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "child died of signal " << WTERMSIG(status);
  ASSERT_EQ(WEXITSTATUS(status), 0) << "see the child's failed check above";

  // The log reads to its end without damage: the first records, then the one after the room.
  std::ifstream in(path, std::ios::binary);
  StreamLogReader reader(in, "gnss.log", StreamLogKind::kBytes);
  std::vector<std::int64_t> stamps;
  while (const auto c = reader.next_bytes()) {
    ASSERT_EQ(c->bytes.size(), kChunk);
    EXPECT_EQ(c->bytes[0], static_cast<std::uint8_t>(c->stamp.ns % 256));
    stamps.push_back(c->stamp.ns);
  }
  EXPECT_EQ(reader.error(), "");
  ASSERT_GE(stamps.size(), static_cast<std::size_t>(kBefore + 1));
  for (int i = 0; i < kBefore; ++i) EXPECT_EQ(stamps[static_cast<std::size_t>(i)], i);
  EXPECT_EQ(stamps.back(), 1000);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace semap::drivers
