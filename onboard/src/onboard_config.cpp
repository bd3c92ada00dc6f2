#include "semap/onboard/onboard_config.hpp"

#include <arpa/inet.h>

#include <cmath>
#include <numbers>

#include "semap/common/config.hpp"
#include "semap/drivers/driver_config.hpp"
#include "semap/onboard/segmenter_factory.hpp"

namespace semap::onboard {

namespace {

using common::ConfigSection;

Eigen::Vector3f vector3(const ConfigSection& s, const std::string& key,
                        const Eigen::Vector3f& fallback) {
  if (!s.has(key)) return fallback;
  const auto v = s.get<std::vector<double>>(key);
  if (v.size() != 3) s.reject(key, "expected 3 numbers, got " + std::to_string(v.size()));
  return Eigen::Vector3f(static_cast<float>(v[0]), static_cast<float>(v[1]),
                         static_cast<float>(v[2]));
}

void read_rig(const ConfigSection& s, RigConfig& rig) {
  const std::string kind = s.get_choice("kind", "sim", {"sim", "hardware", "replay"});
  rig.kind = kind == "sim"        ? RigKind::kSim
             : kind == "hardware" ? RigKind::kHardware
                                  : RigKind::kReplay;
  rig.replay = s.get<std::string>("replay", "");
  if (rig.kind == RigKind::kReplay && rig.replay.empty()) {
    s.reject("replay", "rig.kind: replay needs the recording (FILE.mcap, or an older DIR)");
  }
  if (rig.kind == RigKind::kReplay && !std::filesystem::exists(rig.replay)) {
    s.reject("replay", rig.replay.string() + " does not exist");
  }
  rig.pace = s.get_choice("pace", "recorded", {"recorded", "fast"}) == "fast"
                 ? ReplayPace::kFast
                 : ReplayPace::kRecorded;
  rig.duration_s = s.get_in_range("duration_s", rig.duration_s, 0.0, 86400.0);
}

void read_imu(const ConfigSection& s, ImuSourceConfig& imu) {
  // The driver's keys (profile, base_id, j1939_source, fd_frames, restart_bus_off, reconnect_*)
  // as the driver documents them; an empty interface means no CAN (the simulated rig's ring).
  imu.driver = drivers::can_imu_config(s);
  imu.interface = s.get<std::string>("interface", "");
  imu.driver.interface = imu.interface;
  imu.ring = static_cast<std::size_t>(s.get_in_range("ring", 4096, 16, 1 << 20));
  s.finish();
}

void read_gnss(const ConfigSection& s, GnssSourceConfig& gnss) {
  // The driver's keys (device, baud, vmin, vtime, uere_m, reconnect_*) as the driver documents
  // them; device "pty" means the simulated rig's pseudo-terminal.
  const bool has_device = s.has("device");
  gnss.driver = drivers::gnss_config(s);
  if (!has_device) gnss.driver.serial.device = "pty";
  gnss.device = gnss.driver.serial.device;
  gnss.protocol = s.get_choice("protocol", "nmea", {"nmea", "ubx"}) == "ubx"
                      ? firmware_bridge::GnssProtocol::kUbx
                      : firmware_bridge::GnssProtocol::kNmea;
  if (s.has("lever_arm")) gnss.lever_arm = vector3(s, "lever_arm", Eigen::Vector3f::Zero());
  gnss.ring = static_cast<std::size_t>(s.get_in_range("ring", 256, 16, 65536));
  s.finish();
}

std::size_t ring_size(const ConfigSection& s, std::size_t fallback) {
  const auto n =
      static_cast<std::size_t>(s.get_in_range("ring", static_cast<double>(fallback), 2, 65536));
  if ((n & (n - 1)) != 0) {
    s.reject("ring", std::to_string(n) + " is not a power of two");
  }
  return n;
}

void read_camera(const ConfigSection& s, CameraConfig& cam) {
  cam.driver = drivers::camera_config(s);
  const int width = static_cast<int>(cam.driver.width);
  const int height = static_cast<int>(cam.driver.height);
  if (s.has("fx")) {
    cam.intrinsics.width = width;
    cam.intrinsics.height = height;
    cam.intrinsics.fx = static_cast<float>(s.get_in_range("fx", 0, 1, 1e5));
    cam.intrinsics.fy = static_cast<float>(s.get_in_range("fy", 0, 1, 1e5));
    cam.intrinsics.cx = static_cast<float>(s.get_in_range("cx", 0, 0, width));
    cam.intrinsics.cy = static_cast<float>(s.get_in_range("cy", 0, 0, height));
  } else {
    const double fov = s.get_in_range("fov_deg", 90.0, 10.0, 170.0);
    cam.intrinsics = perception::PinholeIntrinsics::from_fov(
        width, height, static_cast<float>(fov * std::numbers::pi / 180.0));
  }
  cam.mount_xyz = vector3(s, "mount_xyz", cam.mount_xyz);
  cam.mount_rpy_deg = vector3(s, "mount_rpy_deg", cam.mount_rpy_deg);
  cam.ring = ring_size(s, cam.ring);
  s.finish();
}

void read_depth(const ConfigSection& s, const CameraConfig& camera, DepthConfig& depth) {
  depth.source = s.get_choice("source", "aligned", {"aligned", "stereo"}) == "stereo"
                     ? DepthSource::kStereo
                     : DepthSource::kAligned;
  if (depth.source == DepthSource::kAligned) {
    depth.driver = drivers::camera_config(s);
    if (!s.has("format")) depth.driver.format = common::PixelFormat::kZ16;
    if (depth.driver.format != common::PixelFormat::kZ16) {
      s.reject("format", "an aligned depth device delivers Z16");
    }
    // Aligned means pixel for pixel: the size and rate are the colour camera's unless set.
    if (!s.has("width")) depth.driver.width = camera.driver.width;
    if (!s.has("height")) depth.driver.height = camera.driver.height;
    if (!s.has("fps")) depth.driver.fps = camera.driver.fps;
    if (depth.driver.width != camera.driver.width || depth.driver.height != camera.driver.height) {
      s.reject(depth.driver.width != camera.driver.width ? "width" : "height",
               "aligned depth of " + std::to_string(depth.driver.width) + "x" +
                   std::to_string(depth.driver.height) + " does not match the camera's " +
                   std::to_string(camera.driver.width) + "x" +
                   std::to_string(camera.driver.height));
    }
    depth.depth_scale =
        static_cast<float>(s.get_in_range("depth_scale", depth.depth_scale, 1e-6, 1.0));
    depth.sync_tolerance_s =
        s.get_in_range("sync_tolerance_ms", 1e3 * depth.sync_tolerance_s, 0.0, 1000.0) / 1e3;
  } else {
    depth.stereo_calibration = std::filesystem::absolute(s.get<std::string>("calibration"));
    try {
      load_stereo_calibration(depth.stereo_calibration);
    } catch (const std::exception& e) {
      s.reject("calibration", e.what());
    }
    depth.stereo.num_disparities =
        static_cast<int>(s.get_in_range("num_disparities", depth.stereo.num_disparities, 16, 512));
    if (depth.stereo.num_disparities % 16 != 0) {
      s.reject("num_disparities", "must be a multiple of 16");
    }
    depth.stereo.block_size =
        static_cast<int>(s.get_in_range("block_size", depth.stereo.block_size, 1, 31));
    if (depth.stereo.block_size % 2 == 0) {
      s.reject("block_size", "must be odd");
    }
  }
  auto& p = depth.points;
  p.stride = static_cast<int>(s.get_in_range("stride", p.stride, 1, 64));
  p.max_range = static_cast<float>(s.get_in_range("max_range", p.max_range, 0.1, 200.0));
  p.min_confidence =
      static_cast<float>(s.get_in_range("min_confidence", p.min_confidence, 0.0, 1.0));
  p.soft_labels = s.get<bool>("soft_labels", p.soft_labels);
  depth.ring = ring_size(s, depth.ring);
  s.finish();
}

void read_segmenter(const ConfigSection& s, SegmenterConfig& seg) {
  // `onnx` was the only network format once; configs that say so keep working.
  const std::string kind = s.get_choice("kind", "palette", {"dnn", "onnx", "palette", "geometry"});
  seg.kind = kind == "palette"    ? SegmenterConfig::Kind::kPalette
             : kind == "geometry" ? SegmenterConfig::Kind::kGeometry
                                  : SegmenterConfig::Kind::kDnn;
  if (seg.kind == SegmenterConfig::Kind::kDnn) {
    seg.model_card = std::filesystem::absolute(s.get<std::string>("model_card"));
  } else if (seg.kind == SegmenterConfig::Kind::kPalette) {
    if (s.has("palette")) seg.palette = std::filesystem::absolute(s.get<std::string>("palette"));
    seg.confidence = static_cast<float>(s.get_in_range("confidence", seg.confidence, 0.01, 1.0));
  }
  s.finish();
}

void read_segment_rate(const ConfigSection& s, const DepthConfig& depth, SegmentRateConfig& rate) {
  rate.carry_labels = s.get<bool>("carry_labels", rate.carry_labels);
  if (rate.carry_labels && depth.source != DepthSource::kAligned) {
    s.reject("carry_labels", "needs aligned depth (depth.source: aligned)");
  }
  for (const char* key :
       {"segment_hz", "max_label_age_s", "depth_tolerance_m", "depth_tolerance_ratio"}) {
    if (s.has(key) && !rate.carry_labels) s.reject(key, "applies with carry_labels: true only");
  }
  rate.segment_hz = s.get_in_range("segment_hz", rate.segment_hz, 0.0, 1000.0);
  rate.max_label_age_s = s.get_in_range("max_label_age_s", rate.max_label_age_s, 0.01, 60.0);
  auto& carry = rate.carry;
  carry.depth_tolerance_m =
      static_cast<float>(s.get_in_range("depth_tolerance_m", carry.depth_tolerance_m, 0.0, 10.0));
  carry.depth_tolerance_ratio = static_cast<float>(
      s.get_in_range("depth_tolerance_ratio", carry.depth_tolerance_ratio, 0.0, 1.0));
  s.finish();
}

void read_dds(const ConfigSection& s, DdsConfig& dds) {
  dds.enabled = s.get<bool>("enabled", true);
  if (s.has("config")) {
    dds.cyclone_config = std::filesystem::absolute(s.get<std::string>("config"));
  }
  dds.domain = static_cast<int>(s.get_in_range("domain", 0, 0, 232));
  dds.ns = s.get<std::string>("namespace", "");
  dds.frame_id = s.get<std::string>("frame_id", "map");
  dds.base_frame_id = s.get<std::string>("base_frame_id", "base_link");
  dds.sensor_reliability = dds_idl::sensor_reliability_from_string(
      s.get_choice("sensor_reliability", "best_effort", {"best_effort", "reliable"}));
  dds.publish_hz = s.get_in_range("publish_hz", dds.publish_hz, 0.1, 100.0);
  dds.cloud_hz = s.get_in_range("cloud_hz", dds.cloud_hz, 0.0, 10.0);
  dds.odometry_hz = s.get_in_range("odometry_hz", dds.odometry_hz, 1.0, 1000.0);
  dds.stamp_clock = dds_idl::stamp_clock_from_string(
      s.get_choice("stamp_clock", "realtime", {"realtime", "monotonic"}));
  s.finish();
}

void read_viewer(const ConfigSection& s, ViewerConfig& v) {
  v.enabled = s.get<bool>("enabled", v.enabled);
  v.address = s.get<std::string>("address", v.address);
  in6_addr probe{};
  if (inet_pton(AF_INET, v.address.c_str(), &probe) != 1 &&
      inet_pton(AF_INET6, v.address.c_str(), &probe) != 1) {
    s.reject("address",
             "must be an IPv4 or IPv6 address (127.0.0.1: this computer only; "
             "0.0.0.0: every network)");
  }
  const double port = s.get_in_range("port", v.port, 0, 65535);
  if (port != std::floor(port)) s.reject("port", "must be a whole number (0: any free port)");
  v.port = static_cast<int>(port);
  v.token = s.get<std::string>("token", v.token);
  v.client_budget_bytes = static_cast<std::size_t>(s.get_in_range(
      "client_budget_bytes", static_cast<double>(v.client_budget_bytes), 64.0 * 1024, 1e10));
  v.image_hz = s.get_in_range("image_hz", v.image_hz, 0.0, 30.0);
  v.jpeg_quality = static_cast<int>(s.get_in_range("jpeg_quality", v.jpeg_quality, 1, 100));
  s.finish();
}

}  // namespace

OnboardConfig load_onboard_config(const std::filesystem::path& path, const RigKeys& rig_keys) {
  const auto root = ConfigSection::load_file(path);
  OnboardConfig c;
  c.log_level = root.get_choice("log_level", "info", {"trace", "debug", "info", "warn", "error"});
  const auto rig = root.section_or_empty("rig");
  read_rig(rig, c.rig);
  read_imu(root.section_or_empty("imu"), c.imu);
  read_gnss(root.section_or_empty("gnss"), c.gnss);
  read_camera(root.section_or_empty("camera"), c.camera);
  read_depth(root.section_or_empty("depth"), c.camera, c.depth);
  read_segmenter(root.section_or_empty("segmenter"), c.segmenter);
  read_segment_rate(root.section_or_empty("perception"), c.depth, c.perception);
  c.estimator = estimation::load_estimator_config(root.section_or_empty("estimator"));
  const auto map = root.section_or_empty("map");
  c.map.params = mapping::map_params_from_config(map, c.map.params);
  c.map.save_path = map.get<std::string>("save_path", "");
  c.map.palette = map.has("palette") ? mapping::load_palette(map.get<std::string>("palette"),
                                                             c.map.params.num_classes)
                                     : mapping::ClassPalette::defaults(c.map.params.num_classes);
  c.map.checkpoint_path = map.get<std::string>("checkpoint_path", "");
  c.map.checkpoint_s = map.get_in_range("checkpoint_s", c.map.checkpoint_s, 0.0, 3600.0);
  c.map.resume = map.get<bool>("resume", false);
  c.map.memory_radius_m = map.get_in_range("memory_radius_m", 0.0, 0.0, 1e6);
  if (c.map.memory_radius_m > 0.0) {
    // Every block a scan can reach must be in memory when it is inserted.
    const double block_diagonal = std::sqrt(3.0) * c.map.params.block_size();
    const double reach = c.map.params.max_range + c.map.params.ell + block_diagonal;
    if (c.map.params.max_range <= 0.0f || c.map.memory_radius_m < reach) {
      map.reject("memory_radius_m", "must be at least max_range + ell + one block diagonal (" +
                                        std::to_string(reach) + " m), with max_range > 0");
    }
    if (c.map.checkpoint_s <= 0.0) {
      map.reject("memory_radius_m", "needs the checkpoint log (checkpoint_s > 0) to page into");
    }
  }
  c.map.threads = static_cast<int>(map.get_in_range("threads", 2, 1, 64));
  c.map.robot_id = static_cast<mapping::SourceId>(map.get_in_range("robot_id", 1, 1, 65535));
  c.map.start_heading_sigma_deg =
      map.get_in_range("start_heading_sigma_deg", c.map.start_heading_sigma_deg, 0.01, 180.0);
  c.map.hold_seconds = map.get_in_range("hold_seconds", c.map.hold_seconds, 0.0, 600.0);
  c.map.hold_bytes = static_cast<std::size_t>(
      map.get_in_range("hold_bytes", static_cast<double>(c.map.hold_bytes), 0.0, 64e9));
  c.map.hold_heading_sigma_deg =
      map.get_in_range("hold_heading_sigma_deg", c.map.hold_heading_sigma_deg, 0.01, 180.0);
  c.map.hold_lag_s = map.get_in_range("hold_lag_s", c.map.hold_lag_s, 0.0, 600.0);
  c.map.max_position_sigma_m =
      map.get_in_range("max_position_sigma_m", c.map.max_position_sigma_m, 0.0, 1000.0);
  map.finish();
  // Read now: a wrong model path must stop start-up, not leave the robot running without a map.
  try {
    check_segmenter_files(c.segmenter, c.map.params.num_classes);
  } catch (const std::exception& e) {
    const auto segmenter = root.section_or_empty("segmenter");
    segmenter.reject(c.segmenter.kind == SegmenterConfig::Kind::kDnn ? "model_card" : "palette",
                     e.what());
  }
  if (c.gnss.lever_arm) c.estimator.lever_arm = c.gnss.lever_arm->cast<double>();
  read_dds(root.section_or_empty("dds"), c.dds);
  read_viewer(root.section_or_empty("viewer"), c.viewer);
  const auto realtime = root.section_or_empty("realtime");
  c.realtime.lock_memory = realtime.get<bool>("lock_memory", c.realtime.lock_memory);
  if (realtime.has("stage_cpus")) {
    const auto stages = realtime.section("stage_cpus");
    for (const char* stage : {"estimation", "perception", "mapping", "dds"}) {
      if (auto cpus = drivers::cpu_list(stages, stage); !cpus.empty()) {
        c.realtime.stage_cpus[stage] = std::move(cpus);
      }
    }
    stages.finish();
  }
  realtime.finish();
  if (root.has("costmap")) {
    const auto costmap = root.section("costmap");
    CostmapConfig cc;
    cc.params = mapping::costmap_params_from_config(costmap, c.map.palette);
    cc.publish_hz = costmap.get_in_range("publish_hz", cc.publish_hz, 0.1, 50.0);
    costmap.finish();
    c.costmap = cc;
  }
  if (rig_keys) rig_keys(rig, root, c);
  rig.finish();
  root.finish();
  c.map.params.validate_semantic();
  return c;
}

void check_paths(const OnboardConfig& config, const std::filesystem::path& config_file) {
  if (config.dds.enabled && !config.dds.cyclone_config.empty() &&
      !std::filesystem::is_regular_file(config.dds.cyclone_config)) {
    throw common::ConfigError(config_file.string() + ": dds.config: " +
                              config.dds.cyclone_config.string() + ": no such file");
  }
  if (const auto dir = std::filesystem::path(config.map.save_path).parent_path(); !dir.empty()) {
    std::error_code error;
    std::filesystem::create_directories(dir, error);
    if (error) {
      throw common::ConfigError("map.save_path: cannot create " + dir.string() + ": " +
                                error.message());
    }
  }
}

}  // namespace semap::onboard
