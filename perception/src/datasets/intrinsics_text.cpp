#include "semap/perception/datasets/intrinsics_text.hpp"

#include <cmath>
#include <optional>

#include "semap/perception/datasets/dataset.hpp"
#include "text_fields.hpp"

namespace semap::perception::datasets {

namespace {

// Image sides up to 32768 pixels: a larger value is a wrong column, not a camera.
bool is_image_side(double v) { return v >= 1.0 && v <= 32768.0 && v == std::floor(v); }

}  // namespace

PinholeIntrinsics read_intrinsics_text(const std::filesystem::path& path) {
  return parse_intrinsics_text(read_text_file(path), path.string());
}

PinholeIntrinsics parse_intrinsics_text(std::string_view text, const std::string& name) {
  std::optional<PinholeIntrinsics> found;
  for (const TextLine& line : text_lines(text)) {
    if (is_blank_or_comment(line.text)) continue;
    const auto fail = [&](const std::string& what) {
      throw DatasetError(at_line(name, line.number) + ": " + what);
    };
    if (found) fail("a second line of numbers; the file holds one camera");
    const std::vector<std::string_view> words = fields(line.text);
    if (words.size() != 4 && words.size() != 6) {
      fail("expected 'fx fy cx cy [width height]', got " + std::to_string(words.size()) +
           " fields");
    }
    double v[6] = {};
    for (std::size_t i = 0; i < words.size(); ++i) {
      if (!parse_number(words[i], v[i]))
        fail("value " + std::to_string(i + 1) + " " + quoted(words[i]) + " is not a number");
    }
    PinholeIntrinsics k;
    k.fx = static_cast<float>(v[0]);
    k.fy = static_cast<float>(v[1]);
    k.cx = static_cast<float>(v[2]);
    k.cy = static_cast<float>(v[3]);
    if (words.size() == 6) {
      if (!is_image_side(v[4]) || !is_image_side(v[5])) {
        fail("width and height must be whole pixels in [1, 32768]");
      }
      k.width = static_cast<int>(v[4]);
      k.height = static_cast<int>(v[5]);
    }
    // Checked as stored: a value beyond float's range comes out infinite, a tiny one 0.
    if (!std::isfinite(k.fx) || !std::isfinite(k.fy) || !std::isfinite(k.cx) ||
        !std::isfinite(k.cy)) {
      fail("a value beyond float range");
    }
    if (k.fx == 0.0f || k.fy == 0.0f) fail("a focal length of 0");
    found = k;
  }
  if (!found) throw DatasetError(name + ": no line 'fx fy cx cy [width height]'");
  return *found;
}

}  // namespace semap::perception::datasets
