#include "bench_inputs.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

#include "semap/perception/palette_segmenter.hpp"
#include "semap/sim/camera.hpp"
#include "semap/sim/world.hpp"
// GCC 12 at -O3 reports a false -Wrestrict in the writer's string concatenation (GCC PR 105329).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wrestrict"
#include "support/onnx_writer.hpp"
#pragma GCC diagnostic pop

namespace semap::bench {

namespace {

// YUYV 4:2:2: Y0 U Y1 V per pixel pair, chroma averaged over the pair.
common::ImageFrame to_yuyv(const cv::Mat& bgr) {
  cv::Mat yuv;
  cv::cvtColor(bgr, yuv, cv::COLOR_BGR2YUV);
  common::ImageFrame f;
  f.format = common::PixelFormat::kYuyv;
  f.width = static_cast<std::uint32_t>(bgr.cols);
  f.height = static_cast<std::uint32_t>(bgr.rows);
  f.stride = 2 * f.width;
  f.data.resize(static_cast<std::size_t>(f.stride) * f.height);
  for (int y = 0; y < yuv.rows; ++y) {
    const auto* p = yuv.ptr<cv::Vec3b>(y);
    std::uint8_t* out = f.data.data() + static_cast<std::size_t>(y) * f.stride;
    for (int x = 0; x + 1 < yuv.cols; x += 2, out += 4) {
      out[0] = p[x][0];
      out[1] = static_cast<std::uint8_t>((p[x][1] + p[x + 1][1] + 1) / 2);
      out[2] = p[x + 1][0];
      out[3] = static_cast<std::uint8_t>((p[x][2] + p[x + 1][2] + 1) / 2);
    }
  }
  return f;
}

}  // namespace

SceneImages render_scene(const onboard::CameraConfig& camera, float depth_scale) {
  // A street 60 m long ahead of the camera, in the simulated world the demo drives through.
  std::vector<Eigen::Vector3d> path;
  for (int i = 0; i <= 60; ++i) path.emplace_back(i, 0.0, 0.0);
  sim::SimWorldOptions world_options;
  world_options.seed = 11;
  const sim::SimWorld world(path, world_options);
  sim::SimCameraOptions options;
  options.intrinsics = camera.intrinsics;
  const auto frame = sim::SimCamera(options).render(world, camera.body_from_optical(), 0);

  SceneImages out;
  out.camera_bgr = frame.bgr;
  // The true classes in their Cityscapes colours, what PaletteSegmenter reads.
  const auto palette = perception::cityscapes_palette();
  out.label_bgr.create(frame.labels.size(), CV_8UC3);
  for (int v = 0; v < frame.labels.rows; ++v) {
    for (int u = 0; u < frame.labels.cols; ++u) {
      const auto id = frame.labels.at<std::uint8_t>(v, u);
      const cv::Vec3b rgb = id < palette.size() ? palette[id].color : cv::Vec3b(0, 0, 0);
      out.label_bgr.at<cv::Vec3b>(v, u) = cv::Vec3b(rgb[2], rgb[1], rgb[0]);
    }
  }
  const cv::Mat z16 = sim::depth_to_z16(frame.depth_m, depth_scale);
  out.z16.format = common::PixelFormat::kZ16;
  out.z16.width = static_cast<std::uint32_t>(z16.cols);
  out.z16.height = static_cast<std::uint32_t>(z16.rows);
  out.z16.stride = 2 * out.z16.width;
  out.z16.data.assign(z16.datastart, z16.dataend);
  out.yuyv = to_yuyv(out.camera_bgr);
  return out;
}

BenchModel write_bench_model(const std::filesystem::path& dir, int width, int height,
                             int num_map_classes, int threads) {
  constexpr int kChannels = 48;
  constexpr int kMiddle = 3;
  BenchModel m;
  m.classes = 8;
  test::write_bytes(dir / "net.onnx", test::segmentation_benchmark_model(height, width, kChannels,
                                                                         m.classes, kMiddle, 14));
  // 2 * multiply-adds of conv3x3/2, conv3x3/2, middle conv3x3 and the 1x1 head (padding k/2).
  const double h1 = (height + 1) / 2, w1 = (width + 1) / 2;
  const double h2 = (h1 + 1) / 2, w2 = (w1 + 1) / 2;
  const double macs = h1 * w1 * kChannels * 3 * 9 + h2 * w2 * kChannels * kChannels * 9 +
                      kMiddle * h2 * w2 * kChannels * kChannels * 9 +
                      h2 * w2 * m.classes * kChannels;
  m.gflops = 2.0 * macs * 1e-9;

  std::ostringstream names, colours, feeds;
  for (int c = 0; c < m.classes; ++c) {
    const char* sep = c ? ", " : "";
    names << sep << 'c' << c;
    colours << sep << 30 * c << ", 0, " << 255 - 30 * c;
    feeds << sep << 'c' << c << ": ";
    if (c + 1 < m.classes) {
      feeds << 1 + c % (num_map_classes - 1);
    } else {
      feeds << "drop";
    }
  }
  m.card = dir / "card.yaml";
  std::ofstream(m.card) << "model: net.onnx\n"
                        << "input:\n"
                        << "  width: " << width << "\n"
                        << "  height: " << height << "\n"
                        << "  channel_order: rgb\n"
                        << "  mean: [0.485, 0.456, 0.406]\n"
                        << "  std: [0.229, 0.224, 0.225]\n"
                        << "output: logits\n"
                        << "threads: " << threads << "\n"
                        << "model_classes:\n"
                        << "  names: [" << names.str() << "]\n"
                        << "  colors: [" << colours.str() << "]\n"
                        << "map:\n"
                        << "  num_classes: " << num_map_classes << "\n"
                        << "  unmapped: drop\n"
                        << "  from_model: {" << feeds.str() << "}\n";
  return m;
}

estimation::StampedPose circle_pose(double t, common::Stamp stamp) {
  constexpr double kRadius = 10.0, kSpeed = 5.0;
  const double a = kSpeed / kRadius * t;
  estimation::StampedPose p;
  p.stamp = stamp;
  p.position = {kRadius * std::cos(a), kRadius * std::sin(a), 0.0};
  p.orientation = Eigen::AngleAxisd(a + std::numbers::pi / 2, Eigen::Vector3d::UnitZ());
  p.velocity = {-kSpeed * std::sin(a), kSpeed * std::cos(a), 0.0};
  return p;
}

}  // namespace semap::bench
