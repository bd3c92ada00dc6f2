#include "semap/perception/segmentation_views.hpp"

#include <stdexcept>

#include "input_image.hpp"

namespace semap::perception {

std::vector<MapClassStyle> map_class_styles(const ModelCard& card) {
  std::vector<MapClassStyle> styles(static_cast<std::size_t>(card.num_map_classes));
  for (const ModelClass& c : card.classes) {
    if (c.map_class == kNoLabel) continue;
    MapClassStyle& style = styles[c.map_class];
    if (style.name.empty()) style.color = c.color;
    style.name += (style.name.empty() ? "" : "+") + c.name;
  }
  for (std::size_t k = 1; k < styles.size(); ++k) {
    if (styles[k].name.empty()) styles[k].name = "class " + std::to_string(k);
  }
  styles[0] = {"no label", cv::Vec3b(0, 0, 0)};
  return styles;
}

cv::Mat label_image(const Segmentation& segmentation) {
  if (segmentation.num_classes > 256) {
    throw std::invalid_argument("label_image: " + std::to_string(segmentation.num_classes) +
                                " map classes do not fit 8-bit ids");
  }
  cv::Mat ids(segmentation.labels.size(), CV_8UC1);
  for (int y = 0; y < ids.rows; ++y) {
    const auto* labels = segmentation.labels.ptr<std::uint16_t>(y);
    auto* out = ids.ptr<std::uint8_t>(y);
    for (int x = 0; x < ids.cols; ++x) {
      out[x] = labels[x] == kNoLabel ? 0 : static_cast<std::uint8_t>(labels[x]);
    }
  }
  return ids;
}

cv::Mat class_overlay(const cv::Mat& bgr, const Segmentation& segmentation,
                      const std::vector<MapClassStyle>& styles) {
  detail::require_bgr_image(bgr, "class_overlay");
  if (bgr.size() != segmentation.labels.size() ||
      styles.size() != static_cast<std::size_t>(segmentation.num_classes)) {
    throw std::invalid_argument("class_overlay: image, labels and styles do not match");
  }
  cv::Mat out = bgr.clone();
  for (int y = 0; y < out.rows; ++y) {
    const auto* labels = segmentation.labels.ptr<std::uint16_t>(y);
    auto* pixel = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < out.cols; ++x) {
      if (labels[x] == kNoLabel) continue;
      const cv::Vec3b& rgb = styles[labels[x]].color;
      for (int c = 0; c < 3; ++c) {
        pixel[x][c] = static_cast<std::uint8_t>((pixel[x][c] + rgb[2 - c] + 1) / 2);
      }
    }
  }
  return out;
}

std::vector<double> class_shares(const Segmentation& segmentation) {
  std::vector<double> shares(static_cast<std::size_t>(segmentation.num_classes), 0.0);
  const double total = static_cast<double>(segmentation.labels.total());
  for (int y = 0; y < segmentation.labels.rows; ++y) {
    const auto* labels = segmentation.labels.ptr<std::uint16_t>(y);
    for (int x = 0; x < segmentation.labels.cols; ++x) {
      shares[labels[x] == kNoLabel ? 0 : labels[x]] += 1.0;
    }
  }
  for (double& s : shares) s /= total;
  return shares;
}

}  // namespace semap::perception
