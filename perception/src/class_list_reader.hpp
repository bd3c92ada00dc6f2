#pragma once

// Reading class lists from YAML, shared by model cards and palette files: both list classes
// as parallel lists (names, r g b colours, map classes) that ConfigSection reads strictly.

#include <cstddef>
#include <cstdint>
#include <opencv2/core/matx.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "semap/common/config.hpp"

namespace semap::perception::detail {

// A non-empty list of distinct names.
std::vector<std::string> read_class_names(const common::ConfigSection& s, const std::string& key);

// `count` colours as a flat list of r, g, b triples, each an integer in 0..255.
std::vector<cv::Vec3b> read_class_colors(const common::ConfigSection& s, const std::string& key,
                                         std::size_t count);

// "drop" -> kNoLabel, an integer in 1..K-1 -> that map class, anything else -> nullopt.
std::optional<std::uint16_t> parse_map_class(std::string_view text, int num_classes);

// What parse_map_class accepts, for error messages: "a map class in 1..K-1 or drop".
std::string map_class_rule(int num_classes);

}  // namespace semap::perception::detail
