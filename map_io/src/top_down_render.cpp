#include <algorithm>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <unordered_map>

#include "semap/common/map_grid.hpp"
#include "semap/map_io/map_export.hpp"
#include "semap/mapping/atomic_file.hpp"

namespace semap::map_io {

namespace {

constexpr int kLegendWidth = 170;
constexpr int kRowHeight = 22;

struct Column {
  double top = -std::numeric_limits<double>::infinity();
  int label = -1;
  float variance = 0.0f;
};

void write_png(const std::filesystem::path& path, const cv::Mat& image) {
  std::vector<std::uint8_t> bytes;
  if (!cv::imencode(".png", image, bytes)) {
    throw std::runtime_error(path.string() + ": PNG encoding failed");
  }
  mapping::write_file_atomically(path, bytes);
}

cv::Scalar bgr(const mapping::Rgb& c) { return {double(c[2]), double(c[1]), double(c[0])}; }

}  // namespace

void write_top_down_pngs(const std::filesystem::path& class_png,
                         const std::filesystem::path& variance_png,
                         const std::vector<OccupiedCell>& cells, double resolution,
                         const mapping::ClassPalette& palette, const TopDownOptions& options) {
  if (cells.empty()) throw std::runtime_error("top-down rendering: the map has no occupied cells");
  // Highest occupied cell of each (x, y) column.
  Eigen::Vector2i lo(std::numeric_limits<int>::max(), std::numeric_limits<int>::max());
  Eigen::Vector2i hi(std::numeric_limits<int>::min(), std::numeric_limits<int>::min());
  std::unordered_map<common::BlockIndex, Column, common::BlockIndexHash> columns;
  for (const OccupiedCell& c : cells) {
    const common::CellIndex cell =
        common::MapGrid(static_cast<float>(resolution), 1).cell_of(c.centre);
    lo = lo.cwiseMin(cell.head<2>());
    hi = hi.cwiseMax(cell.head<2>());
    Column& col = columns[common::BlockIndex{cell.x(), cell.y(), 0}];
    if (c.centre.z() > col.top) col = {c.centre.z(), c.label, c.variance};
  }
  const int s = std::max(1, options.pixels_per_cell);
  const int width = (hi.x() - lo.x() + 1) * s;
  const int height = std::max((hi.y() - lo.y() + 1) * s, kRowHeight * 12);
  float max_var = 0.0f;
  for (const auto& [key, col] : columns) max_var = std::max(max_var, col.variance);
  if (max_var <= 0.0f) max_var = 1.0f;

  cv::Mat classes(height, width + kLegendWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::Mat variance_gray(height, width, CV_8UC1, cv::Scalar(0));
  cv::Mat known(height, width, CV_8UC1, cv::Scalar(0));
  for (const auto& [key, col] : columns) {
    // Image rows grow downwards, map y upwards: north is up.
    const cv::Rect pixel((key.x - lo.x()) * s, (hi.y() - key.y) * s, s, s);
    classes(pixel).setTo(bgr(palette.color(col.label)));
    variance_gray(pixel).setTo(cv::Scalar(255.0 * col.variance / max_var));
    known(pixel).setTo(cv::Scalar(255));
  }

  // Legend: one swatch and name per class present in the map.
  std::vector<int> labels;
  for (const auto& [key, col] : columns) labels.push_back(col.label);
  std::sort(labels.begin(), labels.end());
  labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
  int row = 0;
  for (const int label : labels) {
    const int y = 10 + row++ * kRowHeight;
    cv::rectangle(classes, cv::Rect(width + 10, y, 16, 16), bgr(palette.color(label)), cv::FILLED);
    cv::rectangle(classes, cv::Rect(width + 10, y, 16, 16), cv::Scalar(0, 0, 0), 1);
    cv::putText(classes, palette.name(label), cv::Point(width + 32, y + 13),
                cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  if (!class_png.empty()) write_png(class_png, classes);

  if (variance_png.empty()) return;
  cv::Mat heat;
  cv::applyColorMap(variance_gray, heat, cv::COLORMAP_JET);
  cv::Mat canvas(height, width + kLegendWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  heat.copyTo(canvas(cv::Rect(0, 0, width, height)), known);
  // Colour bar: top = largest variance, bottom = 0.
  const int bar_height = height - 40;
  cv::Mat ramp(bar_height, 1, CV_8UC1);
  for (int i = 0; i < bar_height; ++i) {
    ramp.at<std::uint8_t>(i, 0) =
        cv::saturate_cast<std::uint8_t>(255.0 * (bar_height - 1 - i) / std::max(1, bar_height - 1));
  }
  cv::Mat ramp_color;
  cv::applyColorMap(ramp, ramp_color, cv::COLORMAP_JET);
  cv::resize(ramp_color, ramp_color, cv::Size(20, bar_height), 0, 0, cv::INTER_NEAREST);
  ramp_color.copyTo(canvas(cv::Rect(width + 10, 20, 20, bar_height)));
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", static_cast<double>(max_var));
  cv::putText(canvas, text, cv::Point(width + 36, 30), cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(canvas, "0", cv::Point(width + 36, 20 + bar_height), cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(canvas, "variance", cv::Point(width + 36, 20 + bar_height / 2),
              cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  write_png(variance_png, canvas);
}

}  // namespace semap::map_io
