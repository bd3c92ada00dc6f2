#include "text_fields.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>

#include "semap/perception/datasets/dataset.hpp"

namespace semap::perception::datasets {

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

}  // namespace

std::string read_text_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DatasetError(path.string() + ": cannot open");
  return {std::istreambuf_iterator<char>(in), {}};
}

std::vector<TextLine> text_lines(std::string_view text) {
  std::vector<TextLine> lines;
  int number = 0;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    lines.push_back({++number, trim(text.substr(0, end))});
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
  }
  return lines;
}

bool is_blank_or_comment(std::string_view line) {
  line = trim(line);
  return line.empty() || line.front() == '#';
}

std::vector<std::string_view> fields(std::string_view line) {
  const auto separator = [](char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; };
  std::vector<std::string_view> out;
  std::size_t pos = 0;
  while (true) {
    while (pos < line.size() && separator(line[pos])) ++pos;
    if (pos >= line.size()) return out;
    std::size_t end = pos;
    while (end < line.size() && !separator(line[end])) ++end;
    out.push_back(line.substr(pos, end - pos));
    pos = end;
  }
}

bool parse_number(std::string_view field, double& value) {
  // from_chars rejects a leading '+', which some writers emit.
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  const char* last = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), last, value);
  return !field.empty() && ec == std::errc() && ptr == last && std::isfinite(value);
}

std::string quoted(std::string_view s) {
  constexpr std::size_t kMax = 40;
  std::string out(1, '\'');
  out.append(s.substr(0, kMax));
  out.append(s.size() > kMax ? "...'" : "'");
  return out;
}

std::string at_line(const std::string& name, int line) { return name + ":" + std::to_string(line); }

}  // namespace semap::perception::datasets
