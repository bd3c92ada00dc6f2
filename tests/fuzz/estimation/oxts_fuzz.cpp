// OXTS lines and KITTI timestamps come from files on disk: any bytes must give a record or a
// clear error, never a crash. The first line is parsed as a timestamp, the rest as OXTS.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "semap/estimation/oxts_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::size_t newline = text.find('\n');
  const std::string_view first = text.substr(0, newline);
  std::string error;
  const auto stamp = semap::estimation::parse_kitti_timestamp(first, error);
  if (!stamp && error.empty()) __builtin_trap();  // a refusal must say why
  const std::string_view rest = newline == std::string_view::npos ? text : text.substr(newline + 1);
  const auto record = semap::estimation::parse_oxts_line(rest, error);
  if (!record && error.empty()) __builtin_trap();  // a refusal must say why
  return 0;
}
