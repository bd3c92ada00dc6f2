#include "semap/drivers/append_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace semap::drivers {

namespace {

// A batch goes to the file at this size, or when its first record is this old: small streams
// (GNSS bytes) reach the disk within a second, frames one by one.
constexpr std::size_t kBatchBytes = 64 * 1024;
constexpr auto kBatchAge = std::chrono::seconds(1);

}  // namespace

AppendFile::AppendFile(std::filesystem::path path, std::vector<std::uint8_t> header,
                       std::chrono::steady_clock::duration retry_after)
    : path_(std::move(path)), header_(std::move(header)), retry_after_(retry_after) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw std::runtime_error(path_.string() + ": cannot create: " + std::strerror(errno));
  }
  flush();
}

AppendFile::~AppendFile() {
  flush();
  ::close(fd_);
}

bool AppendFile::append(std::span<const std::uint8_t> head, std::span<const std::uint8_t> data) {
  const auto now = std::chrono::steady_clock::now();
  if (failing_ && now < retry_at_) {
    ++lost_;
    return false;
  }
  if (batch_records_ == 0) batch_started_ = now;
  batch_.insert(batch_.end(), head.begin(), head.end());
  batch_.insert(batch_.end(), data.begin(), data.end());
  ++batch_records_;
  if (failing_ || batch_.size() >= kBatchBytes || now - batch_started_ >= kBatchAge) {
    return drain();
  }
  return true;
}

bool AppendFile::flush() {
  if (failing_ && batch_records_ == 0 && std::chrono::steady_clock::now() < retry_at_) {
    return false;
  }
  return drain();
}

bool AppendFile::drain() {
  // Nothing to write says nothing about the disk: a failing file stays failing.
  if (batch_records_ == 0 && size_ > 0) return !failing_;
  // The header goes in front of the first batch that fits.
  const std::span<const std::uint8_t> parts[] = {
      size_ == 0 ? std::span<const std::uint8_t>(header_) : std::span<const std::uint8_t>(),
      batch_};
  std::uint64_t at = size_;
  int error = 0;
  for (const auto part : parts) {
    std::size_t done = 0;
    while (error == 0 && done < part.size()) {
      const ssize_t n =
          ::pwrite(fd_, part.data() + done, part.size() - done, static_cast<off_t>(at + done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) error = n == 0 ? ENOSPC : errno;
      if (n > 0) done += static_cast<std::size_t>(n);
    }
    at += done;
  }
  const std::uint64_t records = batch_records_;
  batch_.clear();
  batch_records_ = 0;
  if (error == 0) {
    size_ = at;
    records_ += records;
    failing_ = false;
    return true;
  }
  // Cut off what part of the batch went out: the file ends with its last whole record. When
  // even that fails (EIO) the next batch is written over the torn bytes all the same.
  const int cut = ::ftruncate(fd_, static_cast<off_t>(size_));
  static_cast<void>(cut);
  lost_ += records;
  ++failures_;
  failing_ = true;
  retry_at_ = std::chrono::steady_clock::now() + retry_after_;
  error_ = path_.string() + ": write: " + std::strerror(error);
  return false;
}

}  // namespace semap::drivers
