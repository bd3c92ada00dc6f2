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

#include "semap/perception/synthetic_depth_camera.hpp"
#include "semap/perception/synthetic_scene.hpp"
// GCC 12 at -O3 reports a false -Wrestrict in the writer's string concatenation (GCC PR 105329).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wrestrict"
#include "support/onnx_writer.hpp"
#pragma GCC diagnostic pop

namespace semap::bench {

namespace {

// BGR of the scene's classes, the Cityscapes colours of sky (no return), road, building, pole.
constexpr std::array<std::array<std::uint8_t, 3>, 4> kColours = {{
    {180, 130, 70},
    {128, 64, 128},
    {70, 70, 70},
    {153, 153, 153},
}};

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
  perception::SyntheticScene scene;  // body frame: x forward, y left, ground at z = 0
  scene.add_box({14.0f, -8.0f, 0.0f}, {14.5f, 8.0f, 5.0f});  // facade ahead
  scene.add_box({3.0f, 5.0f, 0.0f}, {14.0f, 5.4f, 4.0f});    // wall on the left
  scene.add_box({6.0f, -6.0f, 0.0f}, {10.0f, -4.5f, 6.0f});  // building on the right
  scene.add_cylinder({5.0f, 2.5f}, 0.15f, 4.0f);
  scene.add_cylinder({9.0f, -3.0f}, 0.15f, 5.0f);
  const auto& k = camera.intrinsics;
  const perception::SyntheticDepthCamera rgbd(k, 30.0f);
  const auto image = rgbd.render(scene, camera.body_from_optical(), common::Stamp{});

  SceneImages out;
  out.label_bgr.create(k.height, k.width, CV_8UC3);
  out.z16 = common::ImageFrame{};
  out.z16.format = common::PixelFormat::kZ16;
  out.z16.width = static_cast<std::uint32_t>(k.width);
  out.z16.height = static_cast<std::uint32_t>(k.height);
  out.z16.stride = 2 * out.z16.width;
  out.z16.data.assign(static_cast<std::size_t>(out.z16.stride) * out.z16.height, 0);
  for (std::size_t i = 0; i < image.depth.size(); ++i) {
    const float z = image.depth[i];
    const auto& c = kColours[z > 0.0f ? std::min<std::size_t>(image.labels[i], 3) : 0];
    std::memcpy(out.label_bgr.data + 3 * i, c.data(), 3);
    const auto units = static_cast<std::uint16_t>(std::min(65535.0f, std::round(z / depth_scale)));
    std::memcpy(out.z16.data.data() + 2 * i, &units, sizeof units);
  }
  // Sensor noise, so MJPEG and the network see texture rather than flat colours.
  cv::Mat noise(out.label_bgr.size(), CV_16SC3);
  cv::randn(noise, 0.0, 6.0);
  out.label_bgr.convertTo(out.camera_bgr, CV_16SC3);
  out.camera_bgr += noise;
  out.camera_bgr.convertTo(out.camera_bgr, CV_8UC3);
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
