#include "semap/sim/world.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <numbers>
#include <opencv2/core.hpp>
#include <vector>

#include "semap/perception/sim_classes.hpp"
#include "semap/sim/camera.hpp"

namespace semap::sim {
namespace {

// The world is labelled in the perception library's classes.
using namespace semap::perception;
namespace id = perception::sim_train_id;
constexpr std::array<std::uint8_t, 8> kWorldClasses = {id::kRoad, id::kSidewalk,   id::kBuilding,
                                                       id::kPole, id::kVegetation, id::kTerrain,
                                                       id::kSky,  id::kCar};

// A figure eight as the simulator drives it: two loops of radius r touching at the origin,
// 2r x 4r across, sampled every ~0.1 m and driven twice, so the path meets and repeats itself.
std::vector<Eigen::Vector3d> figure_eight(double r) {
  std::vector<Eigen::Vector3d> path;
  for (int lap = 0; lap < 2; ++lap) {
    for (double side : {1.0, -1.0}) {
      for (double t = 0.0; t < 2.0 * std::numbers::pi; t += 0.1 / r) {
        path.emplace_back(r * std::sin(t), side * (r - r * std::cos(t)), 0.0);
      }
    }
  }
  return path;
}

Eigen::Vector3f tangent(std::span<const Eigen::Vector3d> path, std::size_t i) {
  const std::size_t j = std::min(i + 5, path.size() - 1);
  const std::size_t k = j == i ? i - 5 : i;
  return (path[j] - path[k]).cast<float>().normalized();
}

// The rig's camera: 1.5 m up, 0.3 m forward, pitched 15 degrees down, on a body at the path
// point heading along it.
Eigen::Isometry3f camera_pose(std::span<const Eigen::Vector3d> path, std::size_t i,
                              float extra_yaw = 0.0f) {
  const Eigen::Vector3f t = tangent(path, i);
  const float yaw = std::atan2(t.y(), t.x()) + extra_yaw;
  Eigen::Isometry3f world_from_body = Eigen::Isometry3f::Identity();
  world_from_body.linear() = Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  world_from_body.translation() = path[i].cast<float>();
  Eigen::Isometry3f body_from_optical = Eigen::Isometry3f::Identity();
  body_from_optical.linear() =
      Eigen::AngleAxisf(15.0f * std::numbers::pi_v<float> / 180.0f, Eigen::Vector3f::UnitY())
          .toRotationMatrix() *
      optical_to_flu();
  body_from_optical.translation() = Eigen::Vector3f(0.3f, 0.0f, 1.5f);
  return world_from_body * body_from_optical;
}

class SimWorldTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    path_ = new std::vector<Eigen::Vector3d>(figure_eight(10.0));
    world_ = new SimWorld(*path_);
  }
  static void TearDownTestSuite() {
    delete world_;
    delete path_;
  }
  struct View {
    Eigen::Isometry3f pose;
    SimFrame frame;
  };
  // Frames from n poses spread along the path, looking ahead and to the sides.
  static std::vector<View> tour(const SimCamera& camera, int n) {
    std::vector<View> views;
    const std::array<float, 3> yaws = {0.0f, 0.9f, -0.9f};
    for (int f = 0; f < n; ++f) {
      const std::size_t i = static_cast<std::size_t>(f) * (path_->size() / 2) / n;
      const Eigen::Isometry3f pose = camera_pose(*path_, i, yaws[f % 3]);
      views.push_back({pose, camera.render(*world_, pose, static_cast<std::uint64_t>(f))});
    }
    return views;
  }
  static std::vector<Eigen::Vector3d>* path_;
  static SimWorld* world_;
};
std::vector<Eigen::Vector3d>* SimWorldTest::path_ = nullptr;
SimWorld* SimWorldTest::world_ = nullptr;

TEST_F(SimWorldTest, SameSeedSameWorldAndFrames) {
  const SimWorld again(*path_);
  ASSERT_EQ(again.solids().size(), world_->solids().size());
  ASSERT_GT(again.solids().size(), 50u);
  for (std::size_t i = 0; i < again.solids().size(); ++i) {
    EXPECT_EQ(again.solids()[i].center, world_->solids()[i].center);
    EXPECT_EQ(again.solids()[i].train_id, world_->solids()[i].train_id);
  }
  SimWorldOptions other;
  other.seed = 2;
  EXPECT_NE(SimWorld(*path_, other).solids().front().center, world_->solids().front().center);

  const SimCamera camera;
  const auto pose = camera_pose(*path_, 100);
  const SimFrame a = camera.render(*world_, pose, 7);
  const SimFrame b = camera.render(again, pose, 7);
  EXPECT_EQ(cv::norm(a.bgr, b.bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth_m, b.depth_m, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.labels, b.labels, cv::NORM_INF), 0.0);
  // Another frame index: new noise, same labels.
  const SimFrame c = camera.render(*world_, pose, 8);
  EXPECT_GT(cv::norm(a.bgr, c.bgr, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(a.labels, c.labels, cv::NORM_INF), 0.0);
}

TEST_F(SimWorldTest, DrivingCorridorIsFree) {
  for (std::size_t i = 0; i < path_->size(); i += 5) {
    const Eigen::Vector3f p = (*path_)[i].cast<float>();
    const Eigen::Vector3f t = tangent(*path_, i);
    for (float h : {0.5f, 1.5f, 2.5f}) {
      const auto hit = world_->cast(p + Eigen::Vector3f(0, 0, h), t, 3.0f);
      EXPECT_FALSE(hit) << "solid " << (hit ? hit->solid : -1) << " ahead of path point " << i;
    }
    // Straight down: the road surface at z = 0.
    const auto down =
        world_->cast(p + Eigen::Vector3f(0, 0, 1.5f), -Eigen::Vector3f::UnitZ(), 5.0f);
    ASSERT_TRUE(down);
    EXPECT_EQ(down->solid, -1);
    EXPECT_EQ(down->train_id, id::kRoad);
    EXPECT_NEAR(down->t, 1.5f, 1e-4f);
    EXPECT_EQ(world_->class_at(p + Eigen::Vector3f(0, 0, 1.0f), 0.1f), 0);
    EXPECT_EQ(world_->class_at(p + Eigen::Vector3f(0, 0, 0.05f), 0.1f), sim_map_class(id::kRoad));
  }
}

TEST_F(SimWorldTest, ClassAtInsideSolids) {
  std::map<std::uint8_t, int> checked;
  for (const auto& s : world_->solids()) {
    // Trunks run into their crowns and car bodies touch their cabins: skip those two.
    if (s.material == SimMaterial::kBark || s.material == SimMaterial::kCarBody) continue;
    const std::uint16_t expected = sim_map_class(s.train_id);
    EXPECT_EQ(world_->class_at(s.center, 0.1f), expected) << "solid class " << int(s.train_id);
    ++checked[s.train_id];
  }
  EXPECT_EQ(checked.size(), 4u);  // building, pole, vegetation, car
}

TEST_F(SimWorldTest, AllClassesSeenAndLabelsMatchGeometry) {
  const SimCamera camera;
  const auto views = tour(camera, 9);
  const auto& k = camera.options().intrinsics;
  std::map<int, std::size_t> counts;
  std::size_t building_px = 0;
  std::size_t building_off = 0;
  for (const auto& [pose, frame] : views) {
    for (int v = 0; v < frame.labels.rows; ++v) {
      for (int u = 0; u < frame.labels.cols; ++u) {
        const std::uint8_t label = frame.labels.at<std::uint8_t>(v, u);
        ++counts[label];
        const float z = frame.depth_m.at<float>(v, u);
        if (label != id::kBuilding || z <= 0.0f) continue;
        // The return lies on some building's box, within 4 sigma of the depth noise.
        const Eigen::Vector3f p = pose * (k.ray(static_cast<float>(u), static_cast<float>(v)) * z);
        float nearest = 1e9f;
        for (const auto& s : world_->solids()) {
          if (s.train_id == id::kBuilding) {
            nearest = std::min(nearest, std::abs(s.signed_distance(p)));
          }
        }
        ++building_px;
        if (nearest > 4.0f * (0.001f * z * z + 0.005f) + 0.01f) ++building_off;
      }
    }
  }
  std::printf("label shares over %zu frames:", views.size());
  const double total = static_cast<double>(views.size()) * 640 * 480;
  for (const auto& [label, n] : counts) std::printf(" %d:%.1f%%", label, 100.0 * n / total);
  std::printf("\n");
  for (std::uint8_t c : kWorldClasses) EXPECT_GT(counts[c], 500u) << "class " << int(c);
  EXPECT_EQ(counts.size(), kWorldClasses.size());
  ASSERT_GT(building_px, 1000u);
  EXPECT_LT(static_cast<double>(building_off) / static_cast<double>(building_px), 0.002);
}

// The camera finds solids through screen-space bins, SimWorld::cast through its ground grid:
// both must see the same thing.
TEST_F(SimWorldTest, CameraAgreesWithWorldCast) {
  const SimCamera camera;
  const auto& k = camera.options().intrinsics;
  for (std::size_t i : {std::size_t{0}, path_->size() / 5, path_->size() / 3}) {
    const auto pose = camera_pose(*path_, i, 0.5f);
    const SimFrame frame = camera.render(*world_, pose, 0);
    std::size_t differ = 0;
    for (int v = 0; v < k.height; ++v) {
      for (int u = 0; u < k.width; ++u) {
        // As the camera forms it, to the last bit: an edge pixel may otherwise flip.
        const Eigen::Vector3f ray = k.ray(static_cast<float>(u), static_cast<float>(v));
        const Eigen::Matrix3f r = pose.linear();
        const float len = std::sqrt(ray.x() * ray.x() + ray.y() * ray.y() + 1.0f);
        const Eigen::Vector3f d = (r.col(2) + ray.y() * r.col(1) + ray.x() * r.col(0)) / len;
        const auto hit = world_->cast(pose.translation(), d, camera.options().visual_range);
        differ += (hit ? hit->train_id : id::kSky) != frame.labels.at<std::uint8_t>(v, u);
      }
    }
    EXPECT_EQ(differ, 0u) << "pose " << i;
  }
}

TEST_F(SimWorldTest, ImagesAreSane) {
  const SimCamera camera;
  for (const auto& [pose, frame] : tour(camera, 3)) {
    ASSERT_EQ(frame.bgr.type(), CV_8UC3);
    ASSERT_EQ(frame.depth_m.type(), CV_32FC1);
    ASSERT_EQ(frame.labels.type(), CV_8UC1);
    EXPECT_EQ(frame.bgr.size(), cv::Size(640, 480));
    EXPECT_TRUE(cv::checkRange(frame.depth_m, true, nullptr, 0.0, 40.0 * 1.2));
    cv::Scalar mean;
    cv::Scalar stddev;
    cv::meanStdDev(frame.bgr, mean, stddev);
    for (int c = 0; c < 3; ++c) {
      EXPECT_GT(mean[c], 40.0);
      EXPECT_LT(mean[c], 220.0);
      EXPECT_GT(stddev[c], 20.0);
    }
    const double valid = cv::countNonZero(frame.depth_m) / (640.0 * 480.0);
    EXPECT_GT(valid, 0.3);
  }
}

// Looking straight down from height h at the road, every road pixel has z-depth h exactly.
TEST_F(SimWorldTest, DepthNoiseFollowsTheModel) {
  const SimCamera camera;
  for (float h : {4.0f, 10.0f}) {
    Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
    pose.linear() = Eigen::Vector3f(1, -1, -1).asDiagonal();  // optical z down, x east
    pose.translation() = (*path_)[0].cast<float>() + Eigen::Vector3f(0, 0, h);
    double sum = 0.0;
    double sum2 = 0.0;
    std::size_t n = 0;
    std::size_t road = 0;
    for (std::uint64_t f = 0; f < 3; ++f) {
      const SimFrame frame = camera.render(*world_, pose, f);
      for (int v = 0; v < 480; ++v) {
        for (int u = 0; u < 640; ++u) {
          if (frame.labels.at<std::uint8_t>(v, u) != id::kRoad) continue;
          ++road;
          const float z = frame.depth_m.at<float>(v, u);
          if (z <= 0.0f) continue;
          sum += z - h;
          sum2 += (z - h) * (z - h);
          ++n;
        }
      }
    }
    ASSERT_GT(n, 10000u);
    const double mean = sum / static_cast<double>(n);
    const double sigma = std::sqrt(sum2 / static_cast<double>(n) - mean * mean);
    const double expected = 0.001 * h * h + 0.005;
    const double missing = 1.0 - static_cast<double>(n) / static_cast<double>(road);
    std::printf("depth at %.0f m: mean error %.4f m, sigma %.4f m (model %.4f), missing %.2f%%\n",
                h, mean, sigma, expected, 100.0 * missing);
    EXPECT_LT(std::abs(mean), 0.05 * expected);
    EXPECT_NEAR(sigma, expected, 0.05 * expected);
    EXPECT_NEAR(missing, 0.005, 0.002);
  }
}

// A long drive that never comes back (the simulator's car scenario covers kilometres): the
// world stays a strip along the road, built in about a second, not a filled bounding box.
TEST(SimWorld, LongDriveStaysAStrip) {
  std::vector<Eigen::Vector3d> path;
  for (double s = 0.0; s < 3000.0; s += 0.5) {
    path.emplace_back(s * 0.8, s * 0.6 + 30.0 * std::sin(s / 100.0), 0.0);
  }
  const auto t0 = std::chrono::steady_clock::now();
  const SimWorld world(path);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("3 km drive: world built in %.0f ms, %zu solids\n", ms, world.solids().size());
  EXPECT_GT(world.solids().size(), 500u);
  EXPECT_LT(world.solids().size(), 5000u);
  for (std::size_t i = 0; i < path.size(); i += 20) {
    const Eigen::Vector3f p = path[i].cast<float>() + Eigen::Vector3f(0, 0, 1.5f);
    const auto down = world.cast(p, -Eigen::Vector3f::UnitZ(), 5.0f);
    ASSERT_TRUE(down);
    EXPECT_EQ(down->train_id, id::kRoad);
  }
}

TEST(SimCamera, DepthToZ16) {
  cv::Mat depth = (cv::Mat_<float>(1, 4) << 0.0f, 1.25f, 0.0004f, 100.0f);
  const cv::Mat z16 = depth_to_z16(depth, 0.001f);
  ASSERT_EQ(z16.type(), CV_16UC1);
  EXPECT_EQ(z16.at<std::uint16_t>(0, 0), 0);
  EXPECT_EQ(z16.at<std::uint16_t>(0, 1), 1250);
  EXPECT_EQ(z16.at<std::uint16_t>(0, 2), 0);
  EXPECT_EQ(z16.at<std::uint16_t>(0, 3), 65535);  // saturates
}

TEST_F(SimWorldTest, RenderedDepthToZ16) {
  const SimFrame frame = SimCamera().render(*world_, camera_pose(*path_, 50), 0);
  const cv::Mat z16 = depth_to_z16(frame.depth_m, 0.001f);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const float z = frame.depth_m.at<float>(v, u);
      const float back = 0.001f * z16.at<std::uint16_t>(v, u);
      ASSERT_NEAR(back, z, 0.0005f + 1e-6f * z) << u << "," << v;
    }
  }
}

// Class means differ, yet the nearest-mean colour classifier is often wrong: texture, shading
// and haze make colour alone a poor cue, as it is in real images.
TEST_F(SimWorldTest, ClassesAreNotSeparableByColour) {
  const SimCamera camera;
  const auto views = tour(camera, 6);
  std::map<int, cv::Vec3d> sums;
  std::map<int, double> counts;
  for (const auto& [pose, frame] : views) {
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        const int label = frame.labels.at<std::uint8_t>(v, u);
        sums[label] += cv::Vec3d(frame.bgr.at<cv::Vec3b>(v, u));
        counts[label] += 1.0;
      }
    }
  }
  std::map<int, cv::Vec3d> means;
  std::printf("mean bgr per class:");
  for (const auto& [label, sum] : sums) {
    means[label] = sum / counts[label];
    std::printf(" %d:(%.0f %.0f %.0f)", label, means[label][0], means[label][1], means[label][2]);
  }
  std::printf("\n");
  for (const auto& [a, ma] : means) {
    for (const auto& [b, mb] : means) {
      if (a < b) {
        EXPECT_GT(cv::norm(ma - mb), 3.0) << a << " vs " << b;
      }
    }
  }
  double wrong = 0.0;
  double total = 0.0;
  for (const auto& [pose, frame] : views) {
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        const cv::Vec3d c(frame.bgr.at<cv::Vec3b>(v, u));
        int best = -1;
        double best_d = 1e30;
        for (const auto& [label, m] : means) {
          const double d = cv::norm(c - m);
          if (d < best_d) {
            best_d = d;
            best = label;
          }
        }
        wrong += best != frame.labels.at<std::uint8_t>(v, u) ? 1.0 : 0.0;
        total += 1.0;
      }
    }
  }
  std::printf("nearest-mean-colour classifier: %.1f%% of pixels wrong\n", 100.0 * wrong / total);
  EXPECT_GT(wrong / total, 0.2);
}

double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

// Prints the cost of a frame; no assertion (shared CI machines). CPU time is what one core
// spends; wall time also counts waiting for a core.
TEST_F(SimWorldTest, RenderTime) {
  const SimCamera camera;
  const int n = 10;
  double wall_ms = 0.0;
  double cpu_ms = 0.0;
  for (int f = 0; f < n; ++f) {
    const std::size_t i = static_cast<std::size_t>(f) * path_->size() / (2 * n);
    const auto pose = camera_pose(*path_, i);
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = thread_cpu_ms();
    const SimFrame frame = camera.render(*world_, pose, static_cast<std::uint64_t>(f));
    cpu_ms += thread_cpu_ms() - c0;
    wall_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  const Eigen::Vector2f size = world_->extent().sizes();
  std::printf(
      "render: %.1f ms CPU (%.1f ms wall) per 640x480 frame, one thread, world %.0f x %.0f m, "
      "%zu solids\n",
      cpu_ms / n, wall_ms / n, size.x(), size.y(), world_->solids().size());
}

}  // namespace
}  // namespace semap::sim
