// McapWriter on a disk that fills: a file-size limit (RLIMIT_FSIZE, SIGXFSZ ignored as
// semap-onboard ignores it) makes a chunk's write fail part-way, as ENOSPC does. The writer
// must throw naming the file and errno, cut the torn chunk off, count its messages as lost,
// and write on once there is room; the file then reads to its end with every other message.
// The limit is set in a forked child, which reports each failed check by its exit code.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "semap/drivers/mcap_message_reader.hpp"
#include "semap/drivers/mcap_writer.hpp"

namespace semap::drivers::mcap {
namespace {

namespace fs = std::filesystem;

constexpr rlim_t kLimit = 100 * 1024;

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

[[noreturn]] void record_while_the_disk_fills(const fs::path& path) {
  ::signal(SIGXFSZ, SIG_IGN);
  McapWriterOptions options;
  options.compression = Compression::kNone;  // sizes as written, so the limit falls mid-chunk
  options.chunk_size = 16 * 1024;
  McapWriter writer(path, options);
  const std::uint16_t channel = writer.add_channel(0, "/camera", "cdr");
  const Bytes frame(1000, 0x42);
  std::uint32_t sequence = 0;
  for (; sequence < 40; ++sequence) writer.write(channel, sequence, sequence, sequence, frame);
  set_limit(kLimit);
  std::string error;
  int failures = 0;
  for (int i = 0; i < 200; ++i, ++sequence) {
    try {
      writer.write(channel, sequence, sequence, sequence, frame);
    } catch (const McapWriteError& e) {
      ++failures;
      if (error.empty()) error = e.what();
      require(e.error() == EFBIG, 3, e.what());
    }
  }
  require(failures > 0, 4, "no write failed");
  require(error == path.string() + ": write: " + std::strerror(EFBIG), 5, error);
  require(fs::file_size(path) == writer.file_size() && writer.file_size() <= kLimit, 6,
          "torn chunk or past the limit");
  require(writer.messages_lost() > 0, 7, "no message counted as lost");
  // A crash now: the file reads up to its last whole chunk.
  {
    McapMessageReader reader(path);
    std::uint64_t n = 0;
    while (reader.next()) ++n;
    require(reader.status() == McapReadStatus::kTruncated && n == writer.messages_written(), 8,
            "as crashed: " + std::to_string(n) + " messages, " + reader.error());
  }
  set_limit(RLIM_INFINITY);
  for (int i = 0; i < 10; ++i, ++sequence)
    writer.write(channel, sequence, sequence, sequence, frame);
  writer.close();
  require(writer.messages_written() + writer.messages_lost() == sequence, 9,
          "messages not counted");
  McapMessageReader reader(path);
  std::uint64_t n = 0;
  std::uint32_t last = 0;
  while (const auto m = reader.next()) {
    require(n == 0 || m->message.sequence > last, 10, "out of order");
    require(m->message.data == frame, 11, "wrong data");
    last = m->message.sequence;
    ++n;
  }
  require(reader.status() == McapReadStatus::kEnd, 12, reader.error());
  require(n == writer.messages_written() && last == sequence - 1, 13, "messages after the room");
  ::_exit(0);
}

TEST(McapWriterOnAFullDisk, CutsTheTornChunkOffAndWritesOnWithRoom) {
  const fs::path dir = fs::temp_directory_path() / ("mcap_full_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const pid_t pid = ::fork();
  if (pid == 0) record_while_the_disk_fills(dir / "run.mcap");
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "child died of signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "see the child's failed check above";
  fs::remove_all(dir);
}

TEST(McapWriterOnAFullDisk, DevFullFailsAtTheHeaderNamingFileAndErrno) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "/dev/full is absent";
  try {
    McapWriter writer("/dev/full");
    FAIL() << "no error";
  } catch (const McapWriteError& e) {
    EXPECT_EQ(e.error(), ENOSPC);
    EXPECT_EQ(std::string(e.what()), std::string("/dev/full: write: ") + std::strerror(ENOSPC));
  }
}

}  // namespace
}  // namespace semap::drivers::mcap
