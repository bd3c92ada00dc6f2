#include "semap/perception/palette_segmenter.hpp"

#include <algorithm>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "class_list_reader.hpp"
#include "input_image.hpp"
#include "semap/common/config.hpp"

namespace semap::perception {

namespace {

constexpr std::uint32_t pack(std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  return static_cast<std::uint32_t>(r) << 16 | static_cast<std::uint32_t>(g) << 8 | b;
}
std::uint32_t pack(const cv::Vec3b& rgb) { return pack(rgb[0], rgb[1], rgb[2]); }

struct CityscapesClass {
  const char* name;
  std::uint8_t r, g, b;
};

// Train ids 0..18, names and colours as in the official cityscapesScripts labels.py.
constexpr std::array<CityscapesClass, 19> kCityscapes = {{
    {"road", 128, 64, 128},
    {"sidewalk", 244, 35, 232},
    {"building", 70, 70, 70},
    {"wall", 102, 102, 156},
    {"fence", 190, 153, 153},
    {"pole", 153, 153, 153},
    {"traffic light", 250, 170, 30},
    {"traffic sign", 220, 220, 0},
    {"vegetation", 107, 142, 35},
    {"terrain", 152, 251, 152},
    {"sky", 70, 130, 180},
    {"person", 220, 20, 60},
    {"rider", 255, 0, 0},
    {"car", 0, 0, 142},
    {"truck", 0, 0, 70},
    {"bus", 0, 60, 100},
    {"train", 0, 80, 100},
    {"motorcycle", 0, 0, 230},
    {"bicycle", 119, 11, 32},
}};

}  // namespace

CityscapesMapping cityscapes_default_mapping() {
  constexpr std::uint16_t ground = 1, building = 2, pole = 3, drop = kNoLabel;
  return {ground, ground, building, building, building, pole, pole, pole, building, ground,
          drop,   drop,   drop,     drop,     drop,     drop, drop, drop, drop};
}

std::vector<PaletteEntry> cityscapes_palette(const CityscapesMapping& map_classes) {
  std::vector<PaletteEntry> palette;
  for (std::size_t id = 0; id < kCityscapes.size(); ++id) {
    const CityscapesClass& c = kCityscapes[id];
    palette.push_back({c.name, cv::Vec3b(c.r, c.g, c.b), map_classes[id]});
  }
  return palette;
}

std::vector<PaletteEntry> load_palette_file(const std::filesystem::path& yaml, int num_classes) {
  const auto root = common::ConfigSection::load_file(yaml);
  const auto names = detail::read_class_names(root, "names");
  const auto colors = detail::read_class_colors(root, "colors", names.size());
  const auto map_classes = root.get<std::vector<std::string>>("map_classes");
  if (map_classes.size() != names.size()) {
    root.reject("map_classes", std::to_string(map_classes.size()) +
                                   " entries, expected one per name (" +
                                   std::to_string(names.size()) + ")");
  }
  std::vector<PaletteEntry> palette;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto map_class = detail::parse_map_class(map_classes[i], num_classes);
    if (!map_class) {
      root.reject(
          "map_classes", i,
          "expected " + detail::map_class_rule(num_classes) + ", got '" + map_classes[i] + "'");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (colors[j] == colors[i]) {
        root.reject("colors", 3 * i, "colour of '" + names[i] + "' is already '" + names[j] + "'");
      }
    }
    palette.push_back({names[i], colors[i], *map_class});
  }
  root.finish();
  return palette;
}

PaletteSegmenter::PaletteSegmenter(std::vector<PaletteEntry> palette, int num_classes,
                                   PaletteOptions options)
    : num_classes_(num_classes), options_(options) {
  detail::require_storable_class_count(num_classes, "PaletteSegmenter");
  const float c = options.confidence;
  if (!(c >= 1.0f / static_cast<float>(num_classes - 1) && c <= 1.0f)) {
    throw std::invalid_argument("PaletteSegmenter: confidence " + std::to_string(c) +
                                " outside [1 / (K - 1), 1] for K = " + std::to_string(num_classes));
  }
  for (const PaletteEntry& e : palette) {
    if (e.map_class != kNoLabel && (e.map_class < 1 || e.map_class >= num_classes)) {
      throw std::invalid_argument("PaletteSegmenter: '" + e.name + "' feeds map class " +
                                  std::to_string(e.map_class) + ", outside 1..K-1");
    }
    table_.emplace_back(pack(e.color), e.map_class);
  }
  std::sort(table_.begin(), table_.end());
  const auto twice = std::adjacent_find(table_.begin(), table_.end(),
                                        [](auto& a, auto& b) { return a.first == b.first; });
  if (twice != table_.end()) {
    throw std::invalid_argument("PaletteSegmenter: colour 0x" + cv::format("%06X", twice->first) +
                                " listed twice");
  }
}

std::uint16_t PaletteSegmenter::lookup(std::uint32_t rgb) const {
  const auto it =
      std::lower_bound(table_.begin(), table_.end(), std::make_pair(rgb, std::uint16_t{0}));
  return it != table_.end() && it->first == rgb ? it->second : kNoLabel;
}

Segmentation PaletteSegmenter::segment(const cv::Mat& bgr) {
  detail::require_bgr_image(bgr, "PaletteSegmenter::segment");
  const int k = num_classes_;
  const float c = options_.confidence;
  // The hit classes other than the label share 1 - c; with K = 2 there are none and c = 1.
  const float other = k > 2 ? (1.0f - c) / static_cast<float>(k - 2) : 0.0f;

  Segmentation out;
  out.num_classes = k;
  out.labels.create(bgr.size(), CV_16UC1);
  out.confidence.create(bgr.size(), CV_32FC1);
  if (options_.soft) out.probabilities = cv::Mat::zeros(bgr.size(), CV_32FC(k));

  // Label images come in runs of one colour: remember the last lookup (starting from a key
  // no 24-bit colour has).
  std::uint32_t last_rgb = 0xFFFFFFFF;
  std::uint16_t last_label = kNoLabel;
  for (int y = 0; y < bgr.rows; ++y) {
    const auto* pixel = bgr.ptr<cv::Vec3b>(y);
    auto* labels = out.labels.ptr<std::uint16_t>(y);
    auto* confidence = out.confidence.ptr<float>(y);
    float* p = options_.soft ? out.probabilities.ptr<float>(y) : nullptr;
    for (int x = 0; x < bgr.cols; ++x) {
      const std::uint32_t rgb = pack(pixel[x][2], pixel[x][1], pixel[x][0]);
      if (rgb != last_rgb) {
        last_rgb = rgb;
        last_label = lookup(rgb);
      }
      labels[x] = last_label;
      confidence[x] = last_label == kNoLabel ? 0.0f : c;
      if (p && last_label != kNoLabel) {
        float* px = p + static_cast<std::ptrdiff_t>(x) * k;
        std::fill(px + 1, px + k, other);
        px[last_label] = c;
      }
    }
  }
  return out;
}

std::string PaletteSegmenter::describe() const {
  return "palette segmenter: " + std::to_string(table_.size()) + " colours -> " +
         std::to_string(num_classes_) + " map classes, " +
         (options_.soft ? "soft labels, confidence " + cv::format("%.2f", options_.confidence)
                        : std::string("hard labels"));
}

}  // namespace semap::perception
