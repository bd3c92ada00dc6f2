#include "semap/perception/kitti_calib_text.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>

namespace semap::perception {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// Whitespace-separated tokens of a value.
std::vector<std::string_view> tokens(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t pos = 0;
  while (true) {
    while (pos < s.size() && is_space(s[pos])) ++pos;
    if (pos >= s.size()) return out;
    std::size_t end = pos;
    while (end < s.size() && !is_space(s[end])) ++end;
    out.push_back(s.substr(pos, end - pos));
    pos = end;
  }
}

// Keeps error messages short when a fuzzer or a wrong file puts long lines there.
std::string quoted(std::string_view s) {
  constexpr std::size_t kMax = 32;
  std::string out(1, '\'');
  out.append(s.substr(0, kMax));
  out.append(s.size() > kMax ? "...'" : "'");
  return out;
}

}  // namespace

KittiCalibText::KittiCalibText(std::string_view text, std::string name) : name_(std::move(name)) {
  int line_number = 0;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    const std::string_view line = trim(text.substr(0, end));
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    ++line_number;
    if (line.empty()) continue;
    const std::size_t colon = line.find(':');
    const std::string_view key = colon == std::string_view::npos ? "" : trim(line.substr(0, colon));
    if (key.empty()) {
      throw CalibrationError(name_ + ": line " + std::to_string(line_number) +
                             ": expected 'key: values', got " + quoted(line));
    }
    if (!entries_.emplace(std::string(key), std::string(line.substr(colon + 1))).second) {
      fail(key, "given twice");
    }
  }
}

KittiCalibText KittiCalibText::read(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CalibrationError(path.string() + ": cannot open");
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  return KittiCalibText(text, path.string());
}

std::vector<double> KittiCalibText::numbers(std::string_view key, std::size_t count) const {
  const auto it = entries_.find(key);
  if (it == entries_.end()) fail(key, "missing");
  const std::vector<std::string_view> words = tokens(it->second);
  if (words.size() != count) {
    fail(key,
         "expected " + std::to_string(count) + " numbers, got " + std::to_string(words.size()));
  }
  std::vector<double> values(count);
  for (std::size_t i = 0; i < count; ++i) {
    const char* first = words[i].data();
    const char* last = first + words[i].size();
    const auto [ptr, ec] = std::from_chars(first, last, values[i]);
    if (ec != std::errc() || ptr != last || !std::isfinite(values[i])) {
      fail(key, "value " + std::to_string(i + 1) + " is not a finite number: " + quoted(words[i]));
    }
  }
  return values;
}

cv::Size KittiCalibText::image_size(std::string_view key) const {
  // The bound keeps a corrupt file from asking for gigapixel buffers later.
  constexpr double kMaxSide = 1 << 15;
  const std::vector<double> v = numbers(key, 2);
  for (const double side : v) {
    if (side < 1.0 || side > kMaxSide || side != std::floor(side)) {
      fail(key, "image size must be whole pixels in [1, 32768], got " + std::to_string(side));
    }
  }
  return {static_cast<int>(v[0]), static_cast<int>(v[1])};
}

void KittiCalibText::fail(std::string_view key, const std::string& what) const {
  throw CalibrationError(name_ + ": key '" + std::string(key.substr(0, 32)) + "': " + what);
}

}  // namespace semap::perception
