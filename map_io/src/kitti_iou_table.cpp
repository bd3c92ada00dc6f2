#include "semap/map_io/kitti_iou_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "semap/map_io/semantic_kitti_io.hpp"

namespace semap::map_io {

namespace {

void append_cell(std::string& out, const char* text, std::size_t width) {
  out.append(width + 1 - std::min(width, std::strlen(text)), ' ');
  out.append(text);
}

void append_percent(std::string& out, double fraction, std::size_t width) {
  char text[16];
  if (std::isnan(fraction)) {
    std::snprintf(text, sizeof(text), "n/a");
  } else {
    std::snprintf(text, sizeof(text), "%.1f", 100.0 * fraction);
  }
  append_cell(out, text, width);
}

}  // namespace

// Class 0 (unlabelled) is never scored, as in the SemanticKITTI benchmark.
double kitti_mean_iou(const mapping::ConfusionMatrix& confusion) {
  return confusion.mean_iou_of_present(1);
}

std::string format_kitti_iou_table(std::span<const IouTableRow> rows) {
  std::size_t name_width = std::strlen("method");
  for (const IouTableRow& row : rows) {
    if (row.confusion == nullptr || row.confusion->num_classes() != kKittiClasses) {
      throw std::invalid_argument("IoU table row '" + row.name +
                                  "' needs 20 SemanticKITTI classes");
    }
    name_width = std::max(name_width, row.name.size());
  }
  // Each column as wide as its class name, and at least "100.0".
  std::vector<std::size_t> widths;
  std::string out = "method";
  out.append(name_width - out.size(), ' ');
  for (int c = 1; c < kKittiClasses; ++c) {
    const char* name = kitti_class_names()[static_cast<std::size_t>(c)];
    widths.push_back(std::max<std::size_t>(5, std::strlen(name)));
    append_cell(out, name, widths.back());
  }
  widths.push_back(std::strlen("average"));
  append_cell(out, "average", widths.back());
  out += '\n';
  for (const IouTableRow& row : rows) {
    out += row.name;
    out.append(name_width - row.name.size(), ' ');
    for (int c = 1; c < kKittiClasses; ++c) {
      append_percent(out, row.confusion->iou_if_present(c),
                     widths[static_cast<std::size_t>(c - 1)]);
    }
    append_percent(out, kitti_mean_iou(*row.confusion), widths.back());
    out += '\n';
  }
  return out;
}

}  // namespace semap::map_io
