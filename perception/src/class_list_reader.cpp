#include "class_list_reader.hpp"

#include <charconv>
#include <cmath>
#include <set>

#include "semap/perception/segmentation.hpp"

namespace semap::perception::detail {

std::vector<std::string> read_class_names(const common::ConfigSection& s, const std::string& key) {
  const auto names = s.get<std::vector<std::string>>(key);
  if (names.empty()) s.reject(key, "needs at least one class");
  std::set<std::string> seen;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!seen.insert(names[i]).second) s.reject(key, i, "'" + names[i] + "' appears twice");
  }
  return names;
}

std::vector<cv::Vec3b> read_class_colors(const common::ConfigSection& s, const std::string& key,
                                         std::size_t count) {
  const auto values = s.get<std::vector<double>>(key);
  if (values.size() != 3 * count) {
    s.reject(key, std::to_string(values.size()) + " values, expected r, g, b for each of the " +
                      std::to_string(count) + " classes (" + std::to_string(3 * count) + ")");
  }
  std::vector<cv::Vec3b> colors(count);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    if (!(v >= 0.0 && v <= 255.0) || v != std::floor(v)) {
      s.reject(key, i, "not an integer in 0..255");
    }
    colors[i / 3][static_cast<int>(i % 3)] = static_cast<std::uint8_t>(v);
  }
  return colors;
}

std::optional<std::uint16_t> parse_map_class(std::string_view text, int num_classes) {
  if (text == "drop") return kNoLabel;
  int value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  if (value < 1 || value >= num_classes) return std::nullopt;
  return static_cast<std::uint16_t>(value);
}

std::string map_class_rule(int num_classes) {
  return "a map class in 1.." + std::to_string(num_classes - 1) + " or drop";
}

}  // namespace semap::perception::detail
