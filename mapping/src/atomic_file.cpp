#include "semap/mapping/atomic_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace semap::mapping {

namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& step, int err) {
  throw std::runtime_error(path.string() + ": " + step + ": " + std::strerror(err));
}

// Closes a descriptor on every path out of write_file_atomically.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes) {
  const std::filesystem::path dir =
      path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  // Hidden, unique name next to the target so rename() stays within one file system.
  std::string pattern = dir.string();
  pattern.append("/.").append(path.filename().string()).append(".XXXXXX");
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  Fd fd(::mkstemp(name.data()));
  if (fd.get() < 0) fail(path, "creating temporary file", errno);
  const std::filesystem::path temp(name.data());
  try {
    // Held until close: remove_stale_temporaries leaves a locked temporary alone.
    if (::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) fail(temp, "flock", errno);
    // mkstemp creates 0600; a map is an ordinary document, readable like any other file.
    if (::fchmod(fd.get(), 0644) != 0) fail(temp, "fchmod", errno);
    std::size_t written = 0;
    while (written < bytes.size()) {
      const ssize_t n = ::write(fd.get(), bytes.data() + written, bytes.size() - written);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) fail(temp, "write", errno);
      written += static_cast<std::size_t>(n);
    }
    if (::fsync(fd.get()) != 0) fail(temp, "fsync", errno);
    if (::close(fd.release()) != 0) fail(temp, "close", errno);
    if (::rename(temp.c_str(), path.c_str()) != 0) fail(path, "rename", errno);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    throw;
  }
  Fd dir_fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY));
  if (dir_fd.get() < 0) fail(dir, "open directory", errno);
  if (::fsync(dir_fd.get()) != 0) fail(dir, "fsync directory", errno);
}

std::size_t remove_stale_temporaries(const std::filesystem::path& path,
                                     std::chrono::seconds min_age) {
  const std::filesystem::path dir =
      path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::string prefix(1, '.');
  prefix.append(path.filename().string()).push_back('.');
  std::error_code ec;
  std::filesystem::directory_iterator it(dir, ec);
  if (ec) return 0;
  std::size_t removed = 0;
  const auto now = std::filesystem::file_time_type::clock::now();
  for (const auto& entry : it) {
    const std::string name = entry.path().filename().string();
    // mkstemp's names: the prefix and six characters.
    if (name.size() != prefix.size() + 6 || name.compare(0, prefix.size(), prefix) != 0) continue;
    std::error_code entry_ec;
    if (!entry.is_regular_file(entry_ec)) continue;
    const auto mtime = std::filesystem::last_write_time(entry.path(), entry_ec);
    if (entry_ec || now - mtime < min_age) continue;
    Fd fd(::open(entry.path().c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC));
    if (fd.get() < 0) continue;
    // A live writer holds the lock; a killed one released it with its descriptors.
    if (::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) continue;
    if (::unlink(entry.path().c_str()) == 0) ++removed;
  }
  return removed;
}

}  // namespace semap::mapping
