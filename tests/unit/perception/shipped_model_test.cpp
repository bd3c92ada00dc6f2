// The segmentation network semap ships (models/semap-seg.onnx + its card): OpenCV 4.6's DNN
// loads it, and it labels frames of the demo's street world (seed 7, which training never saw)
// well enough for the map. The figures it prints are those the model card states for its own
// validation worlds, measured here on the demo world.
#include <gtest/gtest.h>

#include <cstdio>
#include <numbers>

#include "semap/perception/dnn_segmenter.hpp"
#include "semap/perception/model_card.hpp"
#include "semap/perception/sim_classes.hpp"
#include "semap/sim/camera.hpp"
#include "semap/sim/world.hpp"

namespace semap::perception {
namespace {

const std::filesystem::path kCard =
    std::filesystem::path(SEMAP_SOURCE_DIR) / "models" / "semap-seg.yaml";

// A figure-eight-like loop of 60 m, like the demo's drive.
std::vector<Eigen::Vector3d> loop_path() {
  std::vector<Eigen::Vector3d> path;
  for (int i = 0; i <= 400; ++i) {
    const double a = 2.0 * std::numbers::pi * i / 400.0;
    path.emplace_back(30.0 * std::sin(a), 15.0 * std::sin(2.0 * a), 0.0);
  }
  return path;
}

TEST(ShippedModel, LoadsAndLabelsTheDemoWorld) {
  const ModelCard card = load_model_card(kCard);
  EXPECT_EQ(card.num_map_classes, kSimMapClasses);
  DnnSegmenter segmenter(card);
  const auto path = loop_path();
  sim::SimWorldOptions options;
  options.seed = 7;
  const sim::SimWorld world(path, options);
  sim::SimCameraOptions camera_options;
  camera_options.seed = 7;
  const sim::SimCamera camera(camera_options);

  // Confusion over the map classes 1..7, true class (rows) against the model's (columns).
  std::array<std::array<std::uint64_t, kSimMapClasses>, kSimMapClasses> confusion{};
  std::uint64_t unlabelled_hits = 0;
  for (int f = 0; f < 12; ++f) {
    const std::size_t i = static_cast<std::size_t>(f) * path.size() / 12;
    const Eigen::Vector3d ahead = path[(i + 2) % path.size()] - path[i];
    const float yaw = static_cast<float>(std::atan2(ahead.y(), ahead.x()));
    Eigen::Isometry3f world_from_optical = Eigen::Isometry3f::Identity();
    world_from_optical.linear() =
        (Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()) *
         Eigen::AngleAxisf(10.0f * std::numbers::pi_v<float> / 180.0f, Eigen::Vector3f::UnitY()))
            .toRotationMatrix() *
        optical_to_flu();
    world_from_optical.translation() = path[i].cast<float>() + Eigen::Vector3f(0, 0, 1.5f);
    const sim::SimFrame frame =
        camera.render(world, world_from_optical, static_cast<std::uint64_t>(f));
    const Segmentation seg = segmenter.segment(frame.bgr);
    ASSERT_EQ(seg.labels.size(), frame.labels.size());
    for (int v = 0; v < frame.labels.rows; ++v) {
      for (int u = 0; u < frame.labels.cols; ++u) {
        const std::uint16_t truth = sim_map_class(frame.labels.at<std::uint8_t>(v, u));
        if (truth == kNoLabel) continue;  // sky
        const std::uint16_t label = seg.labels.at<std::uint16_t>(v, u);
        if (label == kNoLabel) {
          ++unlabelled_hits;
          continue;
        }
        ++confusion[truth][label];
      }
    }
  }
  double iou_sum = 0.0;
  int classes = 0;
  for (int c = 1; c < kSimMapClasses; ++c) {
    std::uint64_t tp = confusion[c][c], row = 0, column = 0;
    for (int j = 1; j < kSimMapClasses; ++j) {
      row += confusion[c][j];
      column += confusion[j][c];
    }
    if (row == 0) continue;
    const double iou = static_cast<double>(tp) / static_cast<double>(row + column - tp);
    std::printf("shipped model, demo world: %-10s IoU %.3f (%llu px)\n",
                std::string(kSimMapClassTable[c].name).c_str(), iou,
                static_cast<unsigned long long>(row));
    iou_sum += iou;
    ++classes;
  }
  const double miou = iou_sum / classes;
  std::printf("shipped model, demo world: pixel mIoU %.3f over %d classes, %llu hits unlabelled\n",
              miou, classes, static_cast<unsigned long long>(unlabelled_hits));
  EXPECT_GE(classes, 6);
  EXPECT_GT(miou, 0.75);  // 0.83 when the model was shipped
}

}  // namespace
}  // namespace semap::perception
