#include "sim_kitti_raw_drive.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "semap/estimation/oxts_writer.hpp"
#include "semap/map_io/semantic_kitti_io.hpp"
#include "semap/perception/lidar_projection.hpp"
#include "semap/perception/sim_classes.hpp"
#include "semap/sim/camera.hpp"

namespace semap::bench {

namespace fs = std::filesystem;

namespace {

// 2011-09-26 13:02:25 UTC, so the files carry a plausible date.
constexpr std::int64_t kEpochNs = 1317042145LL * 1'000'000'000LL;
constexpr int kImuPerPacket = 10;  // 100 Hz simulator, 10 Hz packets as in *_sync drives

std::string frame_name(std::size_t index, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof(name), "%010zu%s", index, extension);
  return name;
}

Eigen::Isometry3d pose_of(const estimation::NavState& s) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = s.rotation;
  t.translation() = s.position;
  return t;
}

// One Velodyne sweep from `world_from_velo` (world z up, ground at 0), in the sensor frame.
std::vector<Eigen::Vector4f> cast_scan(const sim::SimWorld& world,
                                       const Eigen::Isometry3f& world_from_velo,
                                       const SimKittiRawOptions& o) {
  std::vector<Eigen::Vector4f> points;
  const float deg = std::numbers::pi_v<float> / 180.0f;
  for (int b = 0; b < o.beams; ++b) {
    const float elevation =
        (-24.8f + 26.8f * static_cast<float>(b) / static_cast<float>(std::max(o.beams - 1, 1))) *
        deg;
    for (int a = 0; a < o.azimuths; ++a) {
      const float azimuth =
          2.0f * std::numbers::pi_v<float> * static_cast<float>(a) / static_cast<float>(o.azimuths);
      const Eigen::Vector3f d(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      const auto hit =
          world.cast(world_from_velo.translation(), world_from_velo.linear() * d, o.max_range);
      if (!hit) continue;
      const Eigen::Vector3f p = d * hit->t;
      points.emplace_back(p.x(), p.y(), p.z(), 0.5f);
    }
  }
  return points;
}

// Map class ids seen by the rectified camera P = [M | p4] posed at world_from_rect, cast every
// `stride` pixels; 0 where nothing with a map class is seen (sky).
cv::Mat render_labels(const sim::SimWorld& world, const Eigen::Isometry3f& world_from_rect,
                      const perception::KittiCameraCalibration& calib, int stride) {
  const Eigen::Matrix3d m = calib.p_rect.leftCols<3>();
  const Eigen::Matrix3d m_inv = m.inverse();
  // The camera centre of P_rect_02 in the rectified frame of camera 0: -M^-1 p4.
  const Eigen::Vector3f centre = (-m_inv * calib.p_rect.col(3)).cast<float>();
  const Eigen::Vector3f origin = world_from_rect * centre;
  cv::Mat labels(calib.image_size, CV_8UC1, cv::Scalar(0));
  for (int v0 = 0; v0 < labels.rows; v0 += stride) {
    for (int u0 = 0; u0 < labels.cols; u0 += stride) {
      const double u = u0 + 0.5 * stride;
      const double v = v0 + 0.5 * stride;
      const Eigen::Vector3f ray = (m_inv * Eigen::Vector3d(u, v, 1.0)).normalized().cast<float>();
      const auto hit = world.cast(origin, world_from_rect.linear() * ray, 150.0f);
      const std::uint16_t c = hit ? perception::sim_map_class(hit->train_id) : perception::kNoLabel;
      const auto id = static_cast<std::uint8_t>(c == perception::kNoLabel ? 0 : c);
      const cv::Rect block(u0, v0, std::min(stride, labels.cols - u0),
                           std::min(stride, labels.rows - v0));
      labels(block).setTo(cv::Scalar(id));
    }
  }
  return labels;
}

// The simulated colour camera with image_02's pinhole (P_rect_02's left 3x3; no skew).
sim::SimCamera kitti_colour_camera(const perception::KittiCameraCalibration& calib,
                                   std::uint64_t seed) {
  sim::SimCameraOptions options;
  options.intrinsics.width = calib.image_size.width;
  options.intrinsics.height = calib.image_size.height;
  options.intrinsics.fx = static_cast<float>(calib.p_rect(0, 0));
  options.intrinsics.fy = static_cast<float>(calib.p_rect(1, 1));
  options.intrinsics.cx = static_cast<float>(calib.p_rect(0, 2));
  options.intrinsics.cy = static_cast<float>(calib.p_rect(1, 2));
  options.seed = seed;
  return sim::SimCamera(options);
}

void write_png(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image))
    throw std::runtime_error(path.string() + ": cannot write");
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
}

}  // namespace

sim::SimWorld sim_kitti_raw_world(const SimKittiRawDrive& drive,
                                  const SimKittiRawOptions& options) {
  sim::SimWorldOptions world;
  world.seed = options.seed;
  return sim::SimWorld(drive.path, world);
}

SimKittiRawDrive write_sim_kitti_raw_drive(const fs::path& root, const fs::path& kitti_calib,
                                           const SimKittiRawOptions& o) {
  SimKittiRawDrive out;
  out.calib_dir = root / "2011_09_26";
  out.drive_dir = out.calib_dir / "2011_09_26_drive_0001_sync";
  out.labels_dir = out.drive_dir / "labels_02";
  out.image_dir = out.drive_dir / "image_02" / "data";
  for (const char* sub : {"oxts/data", "velodyne_points/data", "labels_02", "image_02/data"}) {
    fs::create_directories(out.drive_dir / sub);
  }
  for (const char* name :
       {"calib_cam_to_cam.txt", "calib_velo_to_cam.txt", "calib_imu_to_velo.txt"}) {
    fs::copy_file(kitti_calib / name, out.calib_dir / name, fs::copy_options::overwrite_existing);
  }
  const auto camera = perception::KittiCameraCalibration::load(
      out.calib_dir / "calib_cam_to_cam.txt", out.calib_dir / "calib_velo_to_cam.txt", 2);
  const Eigen::Isometry3d body_from_velo =
      perception::KittiCalibText::read(out.calib_dir / "calib_imu_to_velo.txt")
          .rigid_transform()
          .inverse();
  const Eigen::Isometry3d velo_from_rect =
      camera.cam_from_lidar.inverse() * Eigen::Isometry3d(camera.r_rect.transpose());
  // Camera 2's centre in the rectified frame of camera 0: -M^-1 p4 of P_rect_02 = [M | p4].
  const Eigen::Vector3d cam2_centre = -camera.p_rect.leftCols<3>().inverse() * camera.p_rect.col(3);
  const sim::SimCamera colour = kitti_colour_camera(camera, o.seed);

  sim::SimulatorConfig sc;
  sc.duration_s = o.duration_s;
  sc.seed = o.seed;
  out.simulation = sim::simulate(sc);
  const auto& truth = out.simulation.truth;
  const auto& imu = out.simulation.imu;
  for (const auto& t : truth) out.path.push_back(t.state.position);
  const sim::SimWorld world = sim_kitti_raw_world(out, o);
  const estimation::LocalEnu enu(out.simulation.origin);
  // World of the street = ENU raised by the IMU height (the street's ground is z = 0).
  Eigen::Isometry3d street_from_enu = Eigen::Isometry3d::Identity();
  street_from_enu.translation().z() = o.imu_height_m;

  std::ofstream oxts_stamps(out.drive_dir / "oxts/timestamps.txt");
  std::ofstream scan_stamps(out.drive_dir / "velodyne_points/timestamps.txt");
  std::size_t packet = 0;
  for (std::size_t end = kImuPerPacket - 1; end < imu.size(); end += kImuPerPacket, ++packet) {
    // The packet: the truth at its stamp and the mean IMU sample of the interval before it.
    common::ImuSample mean = imu[end];
    mean.accel.setZero();
    mean.gyro.setZero();
    for (std::size_t k = end + 1 - kImuPerPacket; k <= end; ++k) {
      mean.accel += imu[k].accel / kImuPerPacket;
      mean.gyro += imu[k].gyro / kImuPerPacket;
    }
    mean.stamp = common::Stamp(imu[end].stamp.ns + kEpochNs);
    const auto record = estimation::oxts_record_from_state(truth[end].state, mean, enu);
    oxts_stamps << estimation::format_kitti_timestamp(record.stamp) << '\n';
    write_text(out.drive_dir / "oxts/data" / frame_name(packet, ".txt"),
               estimation::format_oxts_line(record) + "\n");

    // The scan half-way to the next packet (as the Velodyne's own clock would stamp it).
    const std::size_t at = end + kImuPerPacket / 2;
    if (at >= truth.size()) break;
    const Eigen::Isometry3d street_from_velo =
        street_from_enu * pose_of(truth[at].state) * body_from_velo;
    const auto points = cast_scan(world, street_from_velo.cast<float>(), o);
    map_io::write_kitti_scan(out.drive_dir / "velodyne_points/data" / frame_name(packet, ".bin"),
                             points);
    scan_stamps << estimation::format_kitti_timestamp(common::Stamp(truth[at].stamp.ns + kEpochNs))
                << '\n';
    const Eigen::Isometry3d street_from_rect = street_from_velo * velo_from_rect;
    write_png(out.labels_dir / frame_name(packet, ".png"),
              render_labels(world, street_from_rect.cast<float>(), camera, o.label_stride));
    if (o.colour_images) {
      const Eigen::Isometry3d street_from_cam2 =
          street_from_rect * Eigen::Translation3d(cam2_centre);
      write_png(out.image_dir / frame_name(packet, ".png"),
                colour.render(world, street_from_cam2.cast<float>(), packet).bgr);
    }
    ++out.scans;
  }
  if (!oxts_stamps || !scan_stamps)
    throw std::runtime_error(out.drive_dir.string() + ": write failed");
  return out;
}

}  // namespace semap::bench
