#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace semap::drivers {

// A new file written in whole records by one thread, for recordings that must outlive a full
// disk. Records are gathered in memory and written in batches (at 64 KiB, after a second, or on
// flush). A batch that cannot be written (ENOSPC, EFBIG under a file-size limit with SIGXFSZ
// ignored, EIO) is cut off again, so the file always ends with a whole record and stays
// readable; its records are counted as lost, the error is kept with the file's name and the
// errno text, and new records are dropped (and counted) until `retry_after` has passed, when
// writing is tried again: a recording resumes by itself once the disk has room.
class AppendFile {
 public:
  // Creates or replaces `path` and writes `header` (before the first record, as soon as it
  // fits). Throws std::runtime_error naming the path when the file cannot be created.
  AppendFile(std::filesystem::path path, std::vector<std::uint8_t> header,
             std::chrono::steady_clock::duration retry_after = std::chrono::seconds(1));
  ~AppendFile();  // flushes
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;

  // One record, given in two parts (a head and its data). False when it is lost: dropped while
  // failing, or in a batch whose write failed.
  bool append(std::span<const std::uint8_t> head, std::span<const std::uint8_t> data = {});
  // Writes what is gathered; false when that failed (or the file is failing).
  bool flush();

  // Records and bytes (header included) taken and not lost: in the file, or gathered for it.
  std::uint64_t records() const { return records_ + batch_records_; }
  std::uint64_t bytes() const { return size_ + batch_.size(); }
  std::uint64_t lost() const { return lost_; }          // records not in the file
  std::uint64_t failures() const { return failures_; }  // writes that failed
  bool failing() const { return failing_; }             // the last write failed
  const std::string& error() const { return error_; }   // the last failure's
  const std::filesystem::path& path() const { return path_; }

 private:
  bool drain();

  std::filesystem::path path_;
  std::vector<std::uint8_t> header_;
  std::chrono::steady_clock::duration retry_after_;
  int fd_ = -1;
  std::vector<std::uint8_t> batch_;
  std::uint64_t batch_records_ = 0;
  std::chrono::steady_clock::time_point batch_started_{};
  std::uint64_t size_ = 0;  // whole records (and the header) in the file
  std::uint64_t records_ = 0;
  std::uint64_t lost_ = 0;
  std::uint64_t failures_ = 0;
  bool failing_ = false;
  std::chrono::steady_clock::time_point retry_at_{};
  std::string error_;
};

}  // namespace semap::drivers
