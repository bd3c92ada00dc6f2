#include "semap/firmware_bridge/candump_reader.hpp"

#include <stdexcept>

namespace semap::firmware_bridge {

CandumpReader::CandumpReader(std::istream& in, std::string name)
    : in_(in), name_(std::move(name)) {}

std::optional<SemapCandumpRecord> CandumpReader::next() {
  while (error_.empty()) {
    text_.clear();
    ++line_;
    bool newline = false;
    // Char by char with a cap, so that a corrupt log without newlines is never held whole.
    for (int c = in_.get(); c != std::char_traits<char>::eof(); c = in_.get()) {
      if (c == '\n') {
        newline = true;
        break;
      }
      if (text_.size() > SEMAP_CANDUMP_MAX_LINE) {
        error_ = name_ + ":" + std::to_string(line_) + ": line: too_long (over " +
                 std::to_string(SEMAP_CANDUMP_MAX_LINE) + " characters)";
        return std::nullopt;
      }
      text_.push_back(static_cast<char>(c));
    }
    if (!newline) {
      if (!text_.empty()) {
        error_ = name_ + ":" + std::to_string(line_) +
                 ": line: truncated (the log ends inside this line, without its newline)";
      }
      return std::nullopt;
    }
    if (text_.find_first_not_of(" \t\r") == std::string::npos) continue;
    SemapCandumpRecord record;
    const SemapFbResult r = semap_candump_parse_line(text_.data(), text_.size(), &record);
    if (r.status == SEMAP_FB_OK) return record;
    // Quoted with unprintable bytes as '?', so a binary file cannot garble the terminal.
    for (char& c : text_) c = (c >= ' ' && c <= '~') ? c : '?';
    error_ = name_ + ":" + std::to_string(line_) + ": " + semap_candump_field_name(r.field) + ": " +
             semap_fb_status_name(r.status) + " in '" + text_ + "'";
  }
  return std::nullopt;
}

std::string format_candump_line(const SemapCandumpRecord& record) {
  char buffer[SEMAP_CANDUMP_MAX_LINE + 2];
  const std::size_t n = semap_candump_format_line(&record, buffer, sizeof buffer);
  if (n == 0) throw std::invalid_argument("CAN record cannot be written as a candump line");
  return {buffer, n};
}

}  // namespace semap::firmware_bridge
