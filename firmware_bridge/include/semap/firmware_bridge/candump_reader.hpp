#pragma once

#include <cstdint>
#include <istream>
#include <optional>
#include <string>

#include "semap/firmware_bridge/candump_log.h"

namespace semap::firmware_bridge {

// Reads a `candump -L` log record by record. A damaged line (malformed, too long, or a last
// line without its newline, as a log cut off mid-write ends) stops the reader; error() then
// names the line and the field: "drive.log:12: data: truncated". Blank lines are skipped.
class CandumpReader {
 public:
  CandumpReader(std::istream& in, std::string name);

  // The next record; nullopt at the end of the log or at the first damage.
  std::optional<SemapCandumpRecord> next();

  // Empty while the log is intact.
  const std::string& error() const { return error_; }
  // Number of the line last read (1-based).
  std::uint64_t line() const { return line_; }

 private:
  std::istream& in_;
  std::string name_;
  std::string error_;
  std::uint64_t line_ = 0;
  std::string text_;
};

// One record as a candump -L line with its newline.
std::string format_candump_line(const SemapCandumpRecord& record);

}  // namespace semap::firmware_bridge
