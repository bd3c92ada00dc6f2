#include "kitti_raw_command.hpp"

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "kitti_raw_drive.hpp"
#include "map_options.hpp"
#include "progress_meter.hpp"
#include "scan_timing.hpp"
#include "semap/common/config.hpp"
#include "semap/common/logging.hpp"
#include "semap/estimation/evaluation.hpp"
#include "semap/estimation/oxts_reader.hpp"
#include "semap/estimation/pose_history.hpp"
#include "semap/estimation/so3.hpp"
#include "semap/map_io/map_export.hpp"
#include "semap/mapping/cloud_transform.hpp"
#include "semap/mapping/semantic_map.hpp"
#include "semap/mapping/smap_io.hpp"
#include "semap/perception/datasets/dataset.hpp"
#include "semap/perception/datasets/velodyne_bin.hpp"
#include "semap/perception/kitti_calib_text.hpp"
#include "semap/perception/lidar_projection.hpp"
#include "top_view.hpp"

namespace semap::apps {

namespace {

namespace fs = std::filesystem;
namespace est = estimation;

struct RawOptions {
  std::string drive;
  std::string calib;
  std::string filter = "inekf";
  std::string gnss_sigma = "1.0";
  std::uint64_t seed = 1;
  std::string segmenter;
  std::string labels;
  std::string out = "kitti_raw";
  int threads = 0;
  std::size_t first = 0;
  std::size_t last = 0;
  double metrics_after = 0.0;
  double initial_yaw_sigma_deg = 5.0;
  double progress_seconds = 5.0;
  MapOptions map;
};

// Map defaults for a Velodyne street scene: coarser than SemanticKITTI's 0.1 m (the camera
// sees a narrow wedge, so fewer points reach each cell) and out to 30 m.
mapping::MapParams kitti_raw_params() {
  mapping::MapParams p;
  p.resolution = 0.2f;
  p.ell = 0.4f;
  p.free_res = 1.0f;
  p.ds_res = 0.2f;
  p.max_range = 30.0f;
  return p;
}

struct ScanStats {
  std::size_t mapped = 0;
  std::size_t without_pose = 0;  // scan stamp outside the filter's trajectory
  std::size_t soft = 0;          // scans inserted with the segmenter's probabilities
  std::uint64_t points = 0;
  std::uint64_t inserted = 0;
  perception::DropCounts drops;
  std::vector<double> label_seconds;   // segmentation + projection
  std::vector<double> insert_seconds;  // S-BKI insert
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// RMSE of the raw fixes against the OXTS positions: what the filters have to beat.
double gnss_ate(const est::DriveData& data) {
  const est::LocalEnu enu(data.origin);
  std::vector<est::Pose3> fixes;
  std::vector<est::Pose3> truth;
  for (std::size_t i = 0; i < data.gnss.size() && i < data.truth.size(); ++i) {
    const auto& f = data.gnss[i];
    est::Pose3 fix;
    fix.position = enu.to_enu({f.latitude_deg, f.longitude_deg, f.altitude_m});
    fixes.push_back(fix);
    est::Pose3 reference;
    reference.position = data.truth[i].state.position;
    truth.push_back(reference);
  }
  return fixes.empty() ? 0.0 : est::ate_rmse(fixes, truth);
}

est::PoseHistory history_of(const est::EvaluationRun& run, common::Stamp start) {
  est::PoseHistory history(std::max<std::size_t>(run.samples.size(), 1));
  for (const auto& s : run.samples) {
    est::StampedPose p;
    p.stamp = common::Stamp(start.ns + static_cast<std::int64_t>(std::llround(s.t * 1e9)));
    p.orientation = Eigen::Quaterniond(s.estimate.rotation);
    p.position = s.estimate.position;
    p.velocity = s.estimate.velocity;
    history.push(p);
  }
  return history;
}

void print_timing(const char* what, std::vector<double> seconds) {
  if (seconds.empty()) return;
  std::sort(seconds.begin(), seconds.end());
  std::printf("%s median %.1f p95 %.1f max %.1f\n", what, percentile_ms(seconds, 0.5),
              percentile_ms(seconds, 0.95), 1e3 * seconds.back());
}

// Each scan posed at its stamp (no deskew: the sweep's 0.1 s of motion is ignored), labelled
// through image_02 and inserted.
ScanStats map_scans(const KittiRawDrive& drive, std::size_t first, std::size_t last,
                    const est::PoseHistory& history, ScanLabelSource& labels,
                    const perception::KittiCameraCalibration& camera,
                    const Eigen::Isometry3f& body_from_velo, mapping::SemanticMap& map,
                    ProgressMeter& meter) {
  ScanStats stats;
  perception::PointOptions options;
  options.max_range = map.params().max_range > 0.0f ? map.params().max_range : 1e9f;
  options.soft_labels = true;
  const std::size_t total = last - first + 1;
  for (std::size_t i = first; i <= last; ++i) {
    meter.update(i - first, total);
    const auto pose = history.at(drive.scan_stamps[i]);
    if (!pose) {
      ++stats.without_pose;
      continue;
    }
    const std::vector<Eigen::Vector4f> raw =
        perception::datasets::read_velodyne_bin(drive.scans[i]);
    std::vector<Eigen::Vector3f> points(raw.size());
    for (std::size_t k = 0; k < raw.size(); ++k) points[k] = raw[k].head<3>();
    auto start = std::chrono::steady_clock::now();
    const perception::Segmentation seg = labels.labels_for(drive.scans[i]);
    common::LabeledCloud body =
        perception::label_lidar_points(points, seg, camera, body_from_velo, options, stats.drops);
    Eigen::Isometry3f world_from_body = Eigen::Isometry3f::Identity();
    world_from_body.linear() = pose->orientation.toRotationMatrix().cast<float>();
    world_from_body.translation() = pose->position.cast<float>();
    common::LabeledCloud cloud = mapping::transform_cloud(body, world_from_body);
    cloud.stamp = drive.scan_stamps[i];
    stats.soft += cloud.has_probabilities() ? 1 : 0;
    stats.label_seconds.push_back(seconds_since(start));
    start = std::chrono::steady_clock::now();
    map.insert(cloud, cloud.origin);
    stats.insert_seconds.push_back(seconds_since(start));
    stats.points += points.size();
    stats.inserted += cloud.size();
    ++stats.mapped;
  }
  meter.update(total, total);
  return stats;
}

void write_map_outputs(const fs::path& out, const mapping::SemanticMap& map) {
  mapping::write_smap(out / "map.smap", map.layers());
  const auto cells = map_io::occupied_cells(map.layers());
  const auto palette = mapping::ClassPalette::defaults(map.params().num_classes);
  map_io::write_ply(out / "map.ply", cells, palette);
  map_io::write_top_down_pngs(out / "map_top_down.png", "", cells, map.params().resolution,
                              palette);
  std::printf("occupied_cells %zu\n", cells.size());
}

int run(const CLI::App& command, const RawOptions& o) {
  const fs::path drive_dir(o.drive);
  const fs::path calib_dir = o.calib.empty() ? drive_dir.parent_path() : fs::path(o.calib);
  std::unique_ptr<tbb::global_control> limit;
  if (o.threads > 0) {
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  static_cast<std::size_t>(o.threads));
  }
  mapping::MapParams params = resolve_map_params(command, o.map, kitti_raw_params());
  const auto camera = perception::KittiCameraCalibration::load(
      calib_dir / "calib_cam_to_cam.txt", calib_dir / "calib_velo_to_cam.txt", 2);
  const Eigen::Isometry3f body_from_velo =
      perception::KittiCalibText::read(calib_dir / "calib_imu_to_velo.txt")
          .rigid_transform()
          .inverse()
          .cast<float>();
  const KittiRawDrive drive = open_kitti_raw_drive(drive_dir);
  std::unique_ptr<ScanLabelSource> labels =
      o.segmenter.empty() ? make_label_image_source(o.labels, params.num_classes)
                          : make_model_label_source(o.segmenter, drive_dir / "image_02" / "data");
  params.num_classes = labels->num_classes();
  params.validate_semantic();

  est::OxtsData oxts;
  try {
    oxts = est::read_oxts_folder(drive_dir / "oxts");
  } catch (const std::runtime_error& e) {
    throw DriveError(e.what());
  }
  if (!oxts.errors.empty()) {
    throw DriveError(oxts.errors.front() +
                     (oxts.errors.size() > 1
                          ? " (and " + std::to_string(oxts.errors.size() - 1) + " more bad packets)"
                          : ""));
  }
  if (oxts.records.size() < 20) {
    throw DriveError((drive_dir / "oxts").string() + ": too few packets (" +
                     std::to_string(oxts.records.size()) + ", at least 20)");
  }
  const bool packet = o.gnss_sigma == "packet";
  const double sigma = packet ? 0.0 : std::stod(o.gnss_sigma);
  const est::DriveData data = est::oxts_to_inputs(
      oxts, sigma, o.seed,
      packet ? est::OxtsGnssNoise::kPacketAccuracy : est::OxtsGnssNoise::kFixedSigma);

  std::printf("drive %s\ncalibration %s\nlabels %s\n", drive_dir.c_str(), calib_dir.c_str(),
              labels->describe().c_str());
  if (packet) {
    std::printf(
        "noise model: GNSS fix = OXTS position + white noise of the packet's pos_accuracy "
        "per axis (floor %.2f m, seed %llu)",
        est::kMinPacketSigmaM, static_cast<unsigned long long>(o.seed));
  } else {
    std::printf(
        "noise model: GNSS fix = OXTS position + white noise sigma %.2f m per axis "
        "(seed %llu)",
        sigma, static_cast<unsigned long long>(o.seed));
  }
  std::printf("; IMU = the packets' accelerations and rates as recorded\n");
  std::printf("OXTS packets %zu over %.1f s, scans %zu\n", oxts.records.size(),
              common::seconds_between(oxts.records.back().stamp, oxts.records.front().stamp),
              drive.scans.size());

  est::EstimatorConfig base;
  base.imu_limits.max_dt_s = std::max(base.imu_limits.max_dt_s, 0.25);  // 10 Hz sync packets
  // The first packet's heading as the initial guess, trusted to a few degrees: left at the
  // default ~uniform sigma, the heading wanders while the car stands and dominates the RMSE
  // until motion makes it observable.
  base.init.yaw_rad = est::yaw_of(data.truth.front().state.rotation);
  base.init.yaw_sigma_rad = o.initial_yaw_sigma_deg * std::numbers::pi / 180.0;
  est::EvaluationOptions eval;
  eval.metrics_after_s = o.metrics_after;
  const auto runs = est::run_filters(data, base, eval, o.filter);
  for (const auto& [name, run] : runs) {
    std::printf("%-5s ATE %.3f m heading_rmse %.3f deg (unaligned, %zu samples after %.0f s)\n",
                name.c_str(), run.metrics.ate_rmse_m, run.metrics.heading_rmse_deg,
                run.metrics.samples, o.metrics_after);
  }
  std::printf("GNSS  ATE %.3f m (the fixes the filters were given)\n", gnss_ate(data));

  fs::create_directories(o.out);
  write_csv(fs::path(o.out) / "trajectory.csv", runs);
  write_top_view(fs::path(o.out) / "top_view.png", data, runs, "OXTS");

  if (drive.scans.empty()) throw DriveError(drive_dir.string() + ": no scans");
  const std::size_t last = command.count("--last") > 0 ? std::min(o.last, drive.scans.size() - 1)
                                                       : drive.scans.size() - 1;
  if (o.first > last) throw DriveError("--first " + std::to_string(o.first) + " beyond the scans");
  // The map follows the first filter run (the InEKF unless --filter eskf).
  const est::PoseHistory history = history_of(runs.front().run, data.imu.front().stamp);
  mapping::SemanticMap map(params);
  ProgressMeter meter("semap-dataset kitti-raw", o.progress_seconds);
  const ScanStats s =
      map_scans(drive, o.first, last, history, *labels, camera, body_from_velo, map, meter);
  const double mapping_seconds = meter.elapsed_seconds();
  std::printf("scans %zu mapped %zu without_pose %zu soft_labelled %zu (posed by %s, no deskew)\n",
              last - o.first + 1, s.mapped, s.without_pose, s.soft, runs.front().name.c_str());
  std::printf(
      "points %llu inserted %llu out_of_image %llu out_of_range %llu no_label %llu "
      "no_depth %llu\n",
      static_cast<unsigned long long>(s.points), static_cast<unsigned long long>(s.inserted),
      static_cast<unsigned long long>(s.drops.out_of_image),
      static_cast<unsigned long long>(s.drops.out_of_range),
      static_cast<unsigned long long>(s.drops.no_label),
      static_cast<unsigned long long>(s.drops.no_depth));
  print_timing("label_ms (segmentation + projection)", s.label_seconds);
  print_timing("insert_ms", s.insert_seconds);
  write_map_outputs(o.out, map);
  std::printf("wall_seconds %.2f threads %zu\n", mapping_seconds,
              tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  return 0;
}

// Errors about the user's files (each names the file): exit status 2.
bool is_bad_input(const std::exception& e) {
  return dynamic_cast<const DriveError*>(&e) != nullptr ||
         dynamic_cast<const perception::CalibrationError*>(&e) != nullptr ||
         dynamic_cast<const perception::datasets::DatasetError*>(&e) != nullptr ||
         dynamic_cast<const common::ConfigError*>(&e) != nullptr;  // model card
}

int run_guarded(const CLI::App& command, const RawOptions& o) {
  try {
    return run(command, o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-dataset kitti-raw: %s\n", e.what());
    return is_bad_input(e) ? 2 : 1;
  }
}

}  // namespace

void add_kitti_raw_command(CLI::App& app) {
  auto options = std::make_shared<RawOptions>();
  RawOptions& o = *options;
  CLI::App* command = app.add_subcommand(
      "kitti-raw",
      "Run the Left-InEKF (and ESKF) on a KITTI raw drive's OXTS-derived IMU and noisy GNSS, "
      "label each Velodyne scan through image_02 and build an S-BKI map; prints unaligned ATE, "
      "heading RMSE and per-scan timing (docs/kitti.md)");
  command
      ->add_option("--drive", o.drive,
                   "a *_sync or *_extract folder (oxts/, velodyne_points/, "
                   "image_02/)")
      ->required();
  command->add_option("--calib", o.calib,
                      "folder with calib_cam_to_cam.txt, calib_velo_to_cam.txt, "
                      "calib_imu_to_velo.txt (default: the drive's parent)");
  command->add_option("--filter", o.filter, "inekf, eskf or both (the map follows the first)")
      ->check(CLI::IsMember({"inekf", "eskf", "both"}));
  command->add_option("--gnss-sigma", o.gnss_sigma,
                      "GNSS white noise per axis, m, or `packet` for each packet's pos_accuracy");
  command->add_option("--seed", o.seed, "seed of the GNSS noise");
  auto* seg =
      command->add_option("--segmenter", o.segmenter, "ONNX model card (YAML) for image_02");
  auto* lab = command->add_option("--labels", o.labels,
                                  "folder of 8-bit class-id PNGs, one per scan (NNNNNNNNNN.png)");
  seg->excludes(lab);
  lab->excludes(seg);
  command->add_option("--out", o.out, "output folder");
  command->add_option("--threads", o.threads, "worker threads (default: all cores)");
  command->add_option("--first", o.first, "first scan (index in velodyne_points/data)");
  command->add_option("--last", o.last, "last scan, included (default: the last)");
  command
      ->add_option("--initial-yaw-sigma-deg", o.initial_yaw_sigma_deg,
                   "sigma of the initial heading (taken from the first packet), deg")
      ->check(CLI::Range(0.1, 360.0));
  command->add_option("--metrics-after", o.metrics_after, "seconds excluded from ATE and heading");
  command->add_option("--progress-seconds", o.progress_seconds,
                      "progress line on stderr every so many seconds (0: none)");
  add_map_parameter_options(*command, o.map);
  command->callback([command, options] {
    common::setup_logging("warn");
    const RawOptions& opts = *options;
    if (opts.segmenter.empty() == opts.labels.empty()) {
      std::fprintf(stderr, "semap-dataset kitti-raw: give one of --segmenter or --labels\n");
      throw CLI::RuntimeError(2);
    }
    if (opts.gnss_sigma != "packet") {
      try {
        if (std::stod(opts.gnss_sigma) <= 0.0) throw std::invalid_argument("not positive");
      } catch (const std::exception&) {
        std::fprintf(stderr,
                     "semap-dataset kitti-raw: --gnss-sigma %s: a positive number or `packet`\n",
                     opts.gnss_sigma.c_str());
        throw CLI::RuntimeError(2);
      }
    }
    const int status = run_guarded(*command, opts);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace semap::apps
