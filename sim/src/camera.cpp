#include "semap/sim/camera.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "screen_bins.hpp"
#include "textures.hpp"

namespace semap::sim {

namespace {

using textures::hash;
using textures::unit;

constexpr float kAmbient = 0.5f;  // sky light on an upward surface
constexpr float kSun = 0.65f;     // direct sunlight on a surface facing the sun

// 2^16 standard normal samples (Box-Muller on hashed uniforms), looked up by a hash: far
// cheaper per pixel than drawing from a distribution.
const std::array<float, 65536>& gaussians() {
  static const std::array<float, 65536> table = [] {
    std::array<float, 65536> t{};
    for (std::uint32_t i = 0; i < t.size(); i += 2) {
      const float u1 = (static_cast<float>(hash(2 * i + 1) >> 8) + 0.5f) / 16777216.0f;
      const float u2 = unit(hash(2 * i + 2));
      const float r = std::sqrt(-2.0f * std::log(u1));
      t[i] = r * std::cos(2.0f * std::numbers::pi_v<float> * u2);
      t[i + 1] = r * std::sin(2.0f * std::numbers::pi_v<float> * u2);
    }
    return t;
  }();
  return table;
}

// Independent random streams of one frame: a pixel's key mixes seed, frame and pixel index.
struct FrameRandom {
  std::uint32_t base;
  std::uint32_t key(std::uint32_t pixel, std::uint32_t stream) const {
    return hash(base ^ hash(pixel * 4u + stream));
  }
};

// Light leaving a surface point towards the camera, r g b: Lambert with sky light weighted
// towards upward faces plus the sun where the surface faces it, fading into the haze with
// distance.
Eigen::Vector3f radiance(const SimWorld& world, const SimHit& hit, const Eigen::Vector3f& p,
                         const Eigen::Vector3f& sun, float fog_distance) {
  const Eigen::Vector3f n = textures::shading_normal(world, hit, p);
  const float light = kAmbient * (0.8f + 0.2f * n.z()) + kSun * std::max(0.0f, n.dot(sun));
  const float fog = std::exp(-hit.t / fog_distance);
  return textures::albedo(world, hit, p) * (light * fog) + textures::haze() * (1.0f - fog);
}

// The depth reported for a hit at z-depth z, or 0: returns go missing beyond max_range, at
// grazing incidence (cos = |n . d| small) and at random; the rest get noise of sigma
// a z^2 + b. `key` is the pixel's random key.
float depth_return(const SimCameraOptions& o, const SimHit& hit, const Eigen::Vector3f& d, float z,
                   float cos_grazing, std::uint32_t key) {
  const float cos_incidence = std::abs(hit.normal.dot(d));
  const float grazing =
      o.grazing_dropout * std::clamp(1.0f - cos_incidence / cos_grazing, 0.0f, 1.0f);
  if (hit.t > o.max_range || unit(hash(key)) < o.dropout + grazing) return 0.0f;
  const float sigma = o.depth_noise_quadratic * z * z + o.depth_noise_floor;
  return std::max(1e-3f, z + sigma * gaussians()[key & 0xFFFFu]);
}

// Sensor noise of `sigma` grey levels on every channel.
void add_noise(cv::Mat& bgr, const FrameRandom& random, float sigma) {
  const auto& gauss = gaussians();
  const int n = 3 * bgr.cols;
  for (int v = 0; v < bgr.rows; ++v) {
    auto* px = bgr.ptr<std::uint8_t>(v);
    for (int i = 0; i < n; ++i) {
      const std::uint32_t h = random.key(static_cast<std::uint32_t>(v * n + i), 1);
      px[i] =
          cv::saturate_cast<std::uint8_t>(static_cast<float>(px[i]) + sigma * gauss[h & 0xFFFFu]);
    }
  }
}

}  // namespace

SimCamera::SimCamera(const SimCameraOptions& options) : options_(options) {}

SimFrame SimCamera::render(const SimWorld& world, const Eigen::Isometry3f& world_from_optical,
                           std::uint64_t frame_index) const {
  const perception::PinholeIntrinsics& k = options_.intrinsics;
  const FrameRandom random{hash(static_cast<std::uint32_t>(options_.seed) ^
                                hash(static_cast<std::uint32_t>(frame_index) * 0x9E3779B9u +
                                     static_cast<std::uint32_t>(options_.seed >> 32)))};
  SimFrame frame;
  frame.bgr.create(k.height, k.width, CV_8UC3);
  frame.depth_m.create(k.height, k.width, CV_32FC1);
  frame.labels.create(k.height, k.width, CV_8UC1);

  const SimScreenBins bins(world.solids(), k, world_from_optical, options_.visual_range);
  const Eigen::Matrix3f r = world_from_optical.linear();
  const Eigen::Vector3f origin = world_from_optical.translation();
  const Eigen::Vector3f sun = world.options().sun_direction.normalized();
  // Auto-exposure never lands exactly: +-6 % per frame.
  const float exposure = 255.0f * (0.94f + 0.12f * unit(hash(random.base + 7u)));
  const float cos_grazing =
      std::cos(options_.grazing_start_deg * std::numbers::pi_v<float> / 180.0f);
  const float half_diagonal2 = 0.25f * static_cast<float>(k.width * k.width + k.height * k.height);

  for (int v = 0; v < k.height; ++v) {
    auto* bgr = frame.bgr.ptr<cv::Vec3b>(v);
    auto* depth = frame.depth_m.ptr<float>(v);
    auto* label = frame.labels.ptr<std::uint8_t>(v);
    const float b = (static_cast<float>(v) - k.cy) / k.fy;
    const Eigen::Vector3f row = r.col(2) + b * r.col(1);
    for (int u = 0; u < k.width; ++u) {
      const float a = (static_cast<float>(u) - k.cx) / k.fx;
      // The optical ray (a, b, 1) has length len; t along the unit ray is depth z = t / len.
      const float len = std::sqrt(a * a + b * b + 1.0f);
      const Eigen::Vector3f d = (row + a * r.col(0)) / len;
      // Solids first: the ground behind one then costs no road lookup.
      const auto solid = bins.cast(world.solids(), u, v, origin, d, options_.visual_range);
      std::optional<SimHit> hit = world.cast_ground(origin, d, solid.t);
      if (solid.solid >= 0 && !(hit && hit->t < solid.t)) {
        hit = world.solid_hit(solid.solid, origin, d, solid.t);
      }
      Eigen::Vector3f colour;
      if (hit) {
        colour = radiance(world, *hit, origin + hit->t * d, sun, options_.fog_distance);
        label[u] = hit->train_id;
        const auto pixel = static_cast<std::uint32_t>(v * k.width + u);
        depth[u] = depth_return(options_, *hit, d, hit->t / len, cos_grazing, random.key(pixel, 0));
      } else {
        colour = textures::sky(d);
        label[u] = perception::sim_train_id::kSky;
        depth[u] = 0.0f;
      }
      // Vignetting: 1 - 0.2 (r / r_corner)^2.
      const float du = static_cast<float>(u) - k.cx;
      const float dv = static_cast<float>(v) - k.cy;
      const float gain = exposure * (1.0f - 0.2f * (du * du + dv * dv) / half_diagonal2);
      for (int c = 0; c < 3; ++c) bgr[u][c] = cv::saturate_cast<std::uint8_t>(colour[2 - c] * gain);
    }
  }
  // Optics blur, then sensor noise.
  cv::GaussianBlur(frame.bgr, frame.bgr, cv::Size(3, 3), 0.0);
  add_noise(frame.bgr, random, options_.image_noise);
  return frame;
}

cv::Mat depth_to_z16(const cv::Mat& depth_m, float depth_scale) {
  cv::Mat z16(depth_m.size(), CV_16UC1);
  for (int v = 0; v < depth_m.rows; ++v) {
    const float* in = depth_m.ptr<float>(v);
    auto* out = z16.ptr<std::uint16_t>(v);
    for (int u = 0; u < depth_m.cols; ++u) {
      const float units = in[u] > 0.0f ? std::round(in[u] / depth_scale) : 0.0f;
      out[u] = static_cast<std::uint16_t>(std::clamp(units, 0.0f, 65535.0f));
    }
  }
  return z16;
}

}  // namespace semap::sim
