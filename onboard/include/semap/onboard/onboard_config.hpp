#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "semap/common/config.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/topic_names.hpp"
#include "semap/drivers/can_imu_driver.hpp"
#include "semap/drivers/gnss_driver.hpp"
#include "semap/estimation/estimator_config.hpp"
#include "semap/firmware_bridge/gnss_protocol.hpp"
#include "semap/mapping/class_palette.hpp"
#include "semap/mapping/layered_map.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/onboard/costmap_output.hpp"
#include "semap/onboard/perception_config.hpp"

namespace semap::onboard {

// Where the sensor streams come from (rig.kind): the built-in simulated rig, the robot's
// devices, or a recording made with --record played back (ReplayRig).
enum class RigKind : std::uint8_t { kSim, kHardware, kReplay };
// How a replay is paced: at the recorded rate, or as fast as the pipeline takes it (each frame
// waits until the stages have taken everything before it, so the run is deterministic).
enum class ReplayPace : std::uint8_t { kRecorded, kFast };

// The sensor rig. A rig's own keys (the simulated rig's drive and world) are read by the library
// that has that rig (see load_onboard_config).
struct RigConfig {
  RigKind kind = RigKind::kSim;
  std::filesystem::path
      replay;  // rig.replay: the MCAP file semap-onboard --record wrote (or an older DIR)
  ReplayPace pace = ReplayPace::kRecorded;
  double duration_s = 40.0;  // 0: run until SIGINT (a replay ends with its recording)
};

struct ImuSourceConfig {
  // Empty: the simulated rig hands IMU samples to the pipeline directly (hosts without vcan);
  // otherwise a CanImuDriver reads this interface (the simulated rig writes to it too).
  std::string interface;
  drivers::CanImuConfig driver;
  std::size_t ring = 4096;
};

struct GnssSourceConfig {
  // "pty": the simulated rig opens a pseudo-terminal and the driver reads its slave side.
  std::string device = "pty";
  drivers::GnssConfig driver;
  firmware_bridge::GnssProtocol protocol = firmware_bridge::GnssProtocol::kNmea;
  std::optional<Eigen::Vector3f> lever_arm;  // antenna in the body frame; overrides estimator's
  std::size_t ring = 256;
};

struct DdsConfig {
  bool enabled = true;
  // Cyclone XML (relative to the working directory, like the other semap apps); exported as
  // CYCLONEDDS_URI unless the environment already sets it.
  std::filesystem::path cyclone_config;
  int domain = 0;
  std::string ns;
  std::string frame_id = "map";
  std::string base_frame_id = "base_link";  // the robot's body frame in odometry and TF
  double publish_hz = 2.0;
  double cloud_hz = 0.5;
  double odometry_hz = 50.0;
  // odometry: best effort (ROS's sensor-data QoS) or reliable, for default ROS subscribers.
  dds_idl::SensorReliability sensor_reliability = dds_idl::SensorReliability::kBestEffort;
  // Header stamps: ROS time (the system clock) or the pipeline's CLOCK_MONOTONIC.
  dds_idl::StampClock stamp_clock = dds_idl::StampClock::kRealtime;
};

// The `viewer:` section: the Foxglove WebSocket server and built-in page (docs/viewer.md).
struct ViewerConfig {
  bool enabled = false;
  // 127.0.0.1: only this computer (an SSH tunnel); 0.0.0.0 exposes it to every network.
  std::string address = "127.0.0.1";
  int port = 8765;    // 0: any free port (the log line "viewer: http://..." says which)
  std::string token;  // non-empty: every request must carry ?token=<token>
  // Bytes waiting to be sent to one client beyond which its droppable messages are dropped.
  std::size_t client_budget_bytes = 8u << 20;
  double image_hz = 2.0;  // camera and overlay images (JPEG) per second, at most
  int jpeg_quality = 75;
};

// The `map:` section: the live map and what the mapping stage does with it.
struct MappingConfig {
  mapping::MapParams params;
  std::string save_path;  // .smap written at exit when set
  // Names and colours of the map's classes (map.palette, a YAML file as semap-export reads),
  // published in MapInfo for planners and viewers.
  mapping::ClassPalette palette;
  // The live map's crash-safe checkpoint (mapping::MapCheckpoint): a block log written every
  // checkpoint_s (0: none). An empty path means <save_path>.log, or map.log in the --report
  // directory, or no checkpoint when neither is given.
  std::string checkpoint_path;
  double checkpoint_s = 10.0;
  bool resume = false;             // continue the map in the checkpoint at start
  double memory_radius_m = 0.0;    // > 0: blocks farther away go to the checkpoint log
  mapping::SourceId robot_id = 1;  // this robot's evidence layer in saved and merged maps
  int threads = 2;
  // Frames are mapped only once the filter's heading is known to within this (1 sigma):
  // a filter that starts from a guessed heading would otherwise smear the map.
  double start_heading_sigma_deg = 3.0;
  // The clouds of frames taken before then are held, the last hold_seconds of them within
  // hold_bytes (the oldest go first, counted), and mapped at the poses the smoother gives
  // their stamps once the heading sigma is below hold_heading_sigma_deg, or at the latest
  // hold_lag_s after it settled (docs/perception.md). 0 seconds or bytes: dropped.
  double hold_seconds = 20.0;
  std::size_t hold_bytes = std::size_t{256} << 20;
  double hold_heading_sigma_deg = 1.0;
  double hold_lag_s = 5.0;
  // Clouds posed while the filter's position sigma (1 sigma, least certain axis) is above this
  // are not mapped: mapping pauses through a long GNSS outage and resumes when fixes return.
  // 0 turns the check off.
  double max_position_sigma_m = 1.0;
};

// realtime: process-wide real-time practice (each driver's thread has its own
// realtime_priority and cpus in its section).
struct RealtimeConfig {
  // mlockall at start: no page fault stalls a thread later; a refusal is logged and reported in
  // the summary, and the robot runs on.
  bool lock_memory = false;
  // `stage_cpus: {estimation: [0], perception: [1], mapping: [1], dds: [0]}`: the CPUs each
  // stage's thread may run on (a stage left out: any). The drivers' are in their sections.
  std::map<std::string, std::vector<int>> stage_cpus;
};

struct OnboardConfig {
  RigConfig rig;
  ImuSourceConfig imu;
  GnssSourceConfig gnss;
  CameraConfig camera;
  DepthConfig depth;
  SegmenterConfig segmenter;
  SegmentRateConfig perception;
  estimation::EstimatorConfig estimator;
  MappingConfig map;
  std::optional<CostmapConfig> costmap;  // the `costmap:` section; published over DDS
  DdsConfig dds;
  ViewerConfig viewer;
  RealtimeConfig realtime;
  std::string log_level = "info";
};

// The keys of the `rig:` section that belong to one rig kind's library, read after every other
// section (so they can be checked against them) and before the section is finished (so a typo
// there is still an error). It may adjust the configuration the rig needs.
using RigKeys = std::function<void(const common::ConfigSection& rig,
                                   const common::ConfigSection& root, OnboardConfig& config)>;

// Reads the whole file strictly: unknown keys, wrong types and out-of-range values throw
// common::ConfigError naming the file, line and key.
OnboardConfig load_onboard_config(const std::filesystem::path& path,
                                  const RigKeys& rig_keys = nullptr);

// Checks what the configuration names on this machine before anything starts (the DDS XML
// exists, the map's directory can be made: a map that cannot be saved at exit would be lost);
// throws common::ConfigError naming the file and key.
void check_paths(const OnboardConfig& config, const std::filesystem::path& config_file);

}  // namespace semap::onboard
