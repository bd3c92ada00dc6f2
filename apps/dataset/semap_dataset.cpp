// semap-dataset: maps a recorded dataset offline with the robot's own perception and mapping
// stages (onboard::Pipeline fed by onboard::DatasetRig), as fast as they go, and writes
// map.smap, map.ply, top.png and summary.json. Exit 2 when anything was skipped.
//   semap-dataset tum DIR --segmenter models/semap-seg.yaml --intrinsics 535.4,539.2,320.1,247.6
//   semap-dataset redwood DIR --no-labels --out out/redwood
//   semap-dataset kitti-odometry sequences/00 --calib calib.txt --no-labels
//   semap-dataset kitti-raw / semantickitti: KITTI raw drives (their own filter on OXTS) and
//   SemanticKITTI evaluation, kitti_raw_command.hpp and kitti_semantic_command.hpp.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <thread>

#include "dataset_report.hpp"
#include "kitti_raw_command.hpp"
#include "kitti_semantic_command.hpp"
#include "semap/common/config.hpp"
#include "semap/common/logging.hpp"
#include "semap/map_io/kitti_semantic_eval.hpp"
#include "semap/onboard/onboard_config.hpp"
#include "semap/perception/datasets/kitti_odometry.hpp"
#include "semap/perception/datasets/redwood.hpp"
#include "semap/perception/datasets/tum.hpp"
#include "semap/perception/model_card.hpp"

namespace {

using namespace semap;
namespace fs = std::filesystem;
namespace datasets = perception::datasets;

struct Options {
  std::string dir;
  std::string segmenter_card;
  std::string labels_dir;
  int num_classes = 0;  // --labels
  bool no_labels = false;
  std::string map_config;
  std::string intrinsics;  // fx,fy,cx,cy
  std::optional<double> depth_scale;
  // Every n-th depth pixel in u and v: at 640x480 a pixel spans millimetres, far below the
  // 5 cm cells, so 2 builds the same map from a quarter of the points.
  int pixel_stride = 2;
  std::string poses;  // kitti-odometry
  std::string calib;  // kitti-odometry
  onboard::DatasetSelection selection;
  std::string out = "out/dataset";
  int threads = 2;
};

perception::PinholeIntrinsics parse_intrinsics(const std::string& text) {
  perception::PinholeIntrinsics k;
  if (std::sscanf(text.c_str(), "%f,%f,%f,%f", &k.fx, &k.fy, &k.cx, &k.cy) != 4) {
    throw std::invalid_argument("--intrinsics: expected fx,fy,cx,cy, got '" + text + "'");
  }
  return k;
}

// Indoor RGB-D: 5 cm cells out to 5 m.
mapping::MapParams rgbd_map() {
  mapping::MapParams p;
  p.resolution = 0.05f;
  p.ell = 0.15f;
  p.free_res = 0.1f;
  p.ds_res = 0.05f;
  p.max_range = 5.0f;
  return p;
}

// A Velodyne street scene at the S-BKI paper's parameters, as semantickitti maps it (ell 0.3,
// ds 0.1), with free space sampled every 2 m and hits kept out to 30 m.
mapping::MapParams lidar_map() {
  mapping::MapParams p = map_io::kitti_semantic_params();
  p.free_res = 2.0f;
  p.max_range = 30.0f;
  return p;
}

int map_classes(const Options& o) {
  if (o.no_labels) return 2;
  if (!o.labels_dir.empty()) return o.num_classes;
  return perception::load_model_card(o.segmenter_card).num_map_classes;
}

// The robot's configuration for an offline run: the map parameters `map`, overridden by the
// keys of --map's map: section (or of the whole file when it has none); no DDS, no
// checkpoint, no costmap; the segmenter the options choose, which sets the class count.
onboard::OnboardConfig pipeline_config(const Options& o, const mapping::MapParams& map) {
  onboard::OnboardConfig c;
  c.map.params = map;
  if (!o.map_config.empty()) {
    const auto root = common::ConfigSection::load_file(o.map_config);
    c.map.params =
        mapping::map_params_from_config(root.has("map") ? root.section("map") : root, map);
  }
  c.map.params.num_classes = map_classes(o);
  c.map.palette = mapping::ClassPalette::defaults(c.map.params.num_classes);
  c.map.params.validate();
  c.map.save_path.clear();
  c.map.checkpoint_s = 0.0;
  c.map.threads = o.threads;
  c.dds.enabled = false;
  c.costmap.reset();
  c.depth.points.max_range = c.map.params.max_range;
  c.depth.ring = 2;
  c.camera.ring = 2;
  if (o.no_labels) {
    c.segmenter.kind = onboard::SegmenterConfig::Kind::kGeometry;
  } else if (!o.labels_dir.empty()) {
    c.segmenter.kind = onboard::SegmenterConfig::Kind::kLabelImage;
  } else {
    c.segmenter.kind = onboard::SegmenterConfig::Kind::kDnn;
    c.segmenter.model_card = o.segmenter_card;
  }
  return c;
}

// --labels DIR: the frame's image is replaced by DIR/<stem>.labels.png (semap-segment's).
fs::path label_image(const Options& o, const fs::path& image) {
  return fs::path(o.labels_dir) / (image.stem().string() + ".labels.png");
}

cv::Size image_size(const fs::path& image) {
  const cv::Mat first = cv::imread(image.string(), cv::IMREAD_UNCHANGED);
  if (first.empty()) throw std::invalid_argument(image.string() + ": cannot read");
  return first.size();
}

// Runs the pipeline over the rig `make_rig` builds, printing progress, and writes the outputs.
int run_pipeline(
    const onboard::OnboardConfig& config, const Options& o,
    const std::function<std::unique_ptr<onboard::DatasetRig>(const onboard::SensorRings&)>&
        make_rig) {
  fs::create_directories(o.out);
  onboard::DatasetRig* rig = nullptr;
  onboard::Pipeline pipeline(config, [&](const onboard::SensorRings& rings) {
    auto made = make_rig(rings);
    rig = made.get();
    return made;
  });
  if (!pipeline.perceiving()) throw std::runtime_error("the segmenter did not load (see above)");

  const auto started = std::chrono::steady_clock::now();
  pipeline.start();
  while (!pipeline.finished()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const auto done = pipeline.mapping().scans;
    const double rate = t > 0 ? static_cast<double>(done) / t : 0.0;
    const double left = static_cast<double>(rig->selected()) - static_cast<double>(done);
    std::fprintf(stderr, "\r%zu/%zu frames mapped, %.1f frames/s, ETA %.0f s   ", done,
                 rig->selected(), rate, rate > 0 ? left / rate : 0.0);
  }
  pipeline.stop();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::fprintf(stderr, "\n");
  const std::size_t skipped = apps::write_dataset_outputs(o.out, pipeline, *rig, wall_s);
  for (const auto& line : pipeline.summary()) std::printf("%s\n", line.c_str());
  std::printf("outputs          : %s/{map.smap, map.ply, top.png, summary.json}\n", o.out.c_str());
  if (skipped > 0) {
    std::printf("skipped          : %zu frames (summary.json names each problem)\n", skipped);
    return 2;
  }
  return 0;
}

int run_rgbd(const std::string& format, const Options& o) {
  datasets::RgbdSequence sequence =
      format == "tum" ? datasets::read_tum(o.dir) : datasets::read_redwood(o.dir);
  if (o.depth_scale) sequence.depth_units_per_metre = *o.depth_scale;
  std::optional<perception::PinholeIntrinsics> intrinsics = sequence.intrinsics;
  if (!o.intrinsics.empty()) intrinsics = parse_intrinsics(o.intrinsics);
  if (!intrinsics && format == "tum") intrinsics = datasets::tum_intrinsics_for(o.dir);
  if (!intrinsics) throw std::invalid_argument("no intrinsics: give --intrinsics fx,fy,cx,cy");
  if (sequence.frames.empty()) throw std::invalid_argument(o.dir + ": no usable frames");
  const cv::Size size = image_size(sequence.frames.front().colour);
  intrinsics->width = size.width;
  intrinsics->height = size.height;
  if (!o.labels_dir.empty()) {
    for (auto& frame : sequence.frames) frame.colour = label_image(o, frame.colour);
  }

  onboard::OnboardConfig config = pipeline_config(o, rgbd_map());
  config.camera.intrinsics = *intrinsics;
  config.depth.source = onboard::DepthSource::kAligned;
  config.depth.points.stride = o.pixel_stride;
  config.depth.depth_scale = static_cast<float>(1.0 / sequence.depth_units_per_metre);
  return run_pipeline(config, o, [&](const onboard::SensorRings& rings) {
    return std::make_unique<onboard::DatasetRig>(std::move(sequence), format + " " + o.dir,
                                                 config.camera.body_from_optical(), o.selection,
                                                 rings);
  });
}

int run_kitti_odometry(const Options& o) {
  datasets::KittiOdometrySequence sequence =
      datasets::read_kitti_odometry(o.dir, o.poses, {.calib = o.calib});
  if (sequence.frames.empty()) throw std::invalid_argument(o.dir + ": no usable scans");
  onboard::OnboardConfig config = pipeline_config(o, lidar_map());
  config.depth.source = onboard::DepthSource::kLidar;
  if (o.no_labels) {
    for (auto& frame : sequence.frames) frame.image.reset();  // whole scans, no image needed
  } else {
    const auto with_image = std::find_if(sequence.frames.begin(), sequence.frames.end(),
                                         [](const auto& f) { return f.image.has_value(); });
    if (with_image == sequence.frames.end()) {
      throw std::invalid_argument(o.dir +
                                  ": no image_2/ to label the scans with: give --no-labels");
    }
    config.depth.lidar.camera = sequence.calib.camera2(image_size(*with_image->image));
    if (!o.labels_dir.empty()) {
      for (auto& frame : sequence.frames) {
        if (frame.image) frame.image = label_image(o, *frame.image);
      }
    }
  }
  return run_pipeline(config, o, [&](const onboard::SensorRings& rings) {
    return std::make_unique<onboard::DatasetRig>(sequence, "kitti-odometry " + o.dir,
                                                 Eigen::Isometry3f::Identity(), o.selection, rings);
  });
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"semap-dataset: a recorded dataset through the robot's perception and mapping"};
  app.require_subcommand(1);
  Options o;
  const auto add_common = [&](CLI::App* command) {
    command->add_option("DIR", o.dir, "the dataset's (or sequence's) folder")
        ->required()
        ->check(CLI::ExistingDirectory);
    auto* card = command
                     ->add_option("--segmenter", o.segmenter_card,
                                  "model card of the network that labels the frames")
                     ->check(CLI::ExistingFile);
    auto* labels =
        command
            ->add_option("--labels", o.labels_dir,
                         "label images made beforehand: DIR/<image stem>.labels.png, map class "
                         "ids, 0 = no label (semap-segment writes them)")
            ->check(CLI::ExistingDirectory);
    auto* classes = command->add_option("--num-classes", o.num_classes,
                                        "with --labels: the map's classes K (ids 1..K-1)");
    classes->check(CLI::Range(2, 256))->needs(labels);
    labels->needs(classes);
    auto* none = command->add_flag("--no-labels", o.no_labels, "geometry only: a 2-class map");
    card->excludes(none)->excludes(labels);
    labels->excludes(none);
    command
        ->add_option("--map", o.map_config,
                     "YAML file whose map: section sets S-BKI parameters (resolution, ell, ...; "
                     "default: the format's)")
        ->check(CLI::ExistingFile);
    command->add_option("--first", o.selection.first, "first frame (index)");
    command->add_option("--last", o.selection.last, "last frame (index)");
    command->add_option("--stride", o.selection.stride, "every n-th frame")
        ->check(CLI::PositiveNumber);
    command->add_option("--out", o.out, "output folder (default out/dataset)");
    command->add_option("--threads", o.threads, "map insert threads")->check(CLI::Range(1, 64));
  };
  const auto add_rgbd = [&](CLI::App* command) {
    add_common(command);
    command->add_option("--intrinsics", o.intrinsics,
                        "fx,fy,cx,cy in pixels (default: the dataset's, if it has them)");
    command
        ->add_option("--depth-scale", o.depth_scale,
                     "raw depth units per metre (default: 5000 TUM, 1000 Redwood)")
        ->check(CLI::PositiveNumber);
    command
        ->add_option("--pixel-stride", o.pixel_stride,
                     "use every n-th depth pixel in u and v (default 2)")
        ->check(CLI::Range(1, 16));
  };
  auto* tum = app.add_subcommand("tum", "TUM RGB-D: rgb.txt, depth.txt, groundtruth.txt");
  auto* redwood = app.add_subcommand(
      "redwood", "Redwood / Open3D: color/, depth/, odometry.log, intrinsic JSON");
  auto* kitti = app.add_subcommand(
      "kitti-odometry", "KITTI odometry sequence: velodyne/, times.txt, calib.txt, poses");
  add_rgbd(tum);
  add_rgbd(redwood);
  add_common(kitti);
  kitti->add_option("--poses", o.poses,
                    "camera-0 poses (default: DIR/poses.txt, else DIR/../../poses/<name>.txt)");
  kitti->add_option("--calib", o.calib, "calib.txt with P2 and Tr (default: DIR/calib.txt)");
  apps::add_kitti_raw_command(app);
  apps::add_kitti_semantic_command(app);
  CLI11_PARSE(app, argc, argv);
  // kitti-raw and semantickitti run as the parse's callbacks (a failure exits with its status).
  if (app.got_subcommand("kitti-raw") || app.got_subcommand("semantickitti")) return 0;
  if (o.segmenter_card.empty() && o.labels_dir.empty() && !o.no_labels) {
    std::cerr << "semap-dataset: give --segmenter CARD, --labels DIR or --no-labels\n";
    return 2;
  }
  common::setup_logging("warn");
  try {
    if (kitti->parsed()) return run_kitti_odometry(o);
    return run_rgbd(tum->parsed() ? "tum" : "redwood", o);
  } catch (const std::exception& e) {
    std::cerr << "\nsemap-dataset: " << e.what() << "\n";
    return 1;
  }
}
