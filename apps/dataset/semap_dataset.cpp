// semap-dataset: maps a recorded dataset offline with the robot's own perception and mapping
// stages (onboard::Pipeline fed by onboard::DatasetRig), as fast as they go, and writes
// map.smap, map.ply, top.png and summary.json. Exit 2 when anything was skipped.
//   semap-dataset tum DIR --segmenter models/semap-seg.yaml --intrinsics 535.4,539.2,320.1,247.6
//   semap-dataset redwood DIR --no-labels --out out/redwood
#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <thread>

#include "dataset_report.hpp"
#include "kitti_raw_command.hpp"
#include "kitti_semantic_command.hpp"
#include "semap/common/logging.hpp"
#include "semap/onboard/onboard_config.hpp"
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
  bool no_labels = false;
  std::string map_config;
  std::string intrinsics;  // fx,fy,cx,cy
  std::optional<double> depth_scale;
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

// A map for indoor RGB-D (5 cm cells, 5 m range) unless --map names the robot's map: section.
onboard::OnboardConfig pipeline_config(const Options& o, int map_classes) {
  onboard::OnboardConfig c;
  if (!o.map_config.empty()) {
    c = onboard::load_onboard_config(o.map_config);
  } else {
    auto& p = c.map.params;
    p.resolution = 0.05f;
    p.ell = 0.15f;
    p.free_res = 0.1f;
    p.ds_res = 0.05f;
    p.max_range = 5.0f;
  }
  c.map.params.num_classes = map_classes;
  c.map.palette = mapping::ClassPalette::defaults(map_classes);
  c.map.params.validate();
  c.map.save_path.clear();
  c.map.checkpoint_s = 0.0;
  c.map.threads = o.threads;
  c.dds.enabled = false;
  c.costmap.reset();
  c.depth.source = onboard::DepthSource::kAligned;
  c.depth.points.max_range = c.map.params.max_range;
  c.depth.ring = 2;
  c.camera.ring = 2;
  if (o.no_labels) {
    c.segmenter.kind = onboard::SegmenterConfig::Kind::kGeometry;
  } else {
    c.segmenter.kind = onboard::SegmenterConfig::Kind::kDnn;
    c.segmenter.model_card = o.segmenter_card;
  }
  return c;
}

int run(const std::string& format, const Options& o) {
  datasets::RgbdSequence sequence =
      format == "tum" ? datasets::read_tum(o.dir) : datasets::read_redwood(o.dir);
  if (o.depth_scale) sequence.depth_units_per_metre = *o.depth_scale;
  std::optional<perception::PinholeIntrinsics> intrinsics = sequence.intrinsics;
  if (!o.intrinsics.empty()) intrinsics = parse_intrinsics(o.intrinsics);
  if (!intrinsics && format == "tum") intrinsics = datasets::tum_intrinsics_for(o.dir);
  if (!intrinsics) throw std::invalid_argument("no intrinsics: give --intrinsics fx,fy,cx,cy");
  if (sequence.frames.empty()) throw std::invalid_argument(o.dir + ": no usable frames");
  const cv::Mat first = cv::imread(sequence.frames.front().colour.string(), cv::IMREAD_COLOR);
  if (first.empty()) {
    throw std::invalid_argument(sequence.frames.front().colour.string() + ": cannot read");
  }
  intrinsics->width = first.cols;
  intrinsics->height = first.rows;

  const int map_classes =
      o.no_labels ? 2 : perception::load_model_card(o.segmenter_card).num_map_classes;
  onboard::OnboardConfig config = pipeline_config(o, map_classes);
  config.camera.intrinsics = *intrinsics;
  config.depth.depth_scale = static_cast<float>(1.0 / sequence.depth_units_per_metre);

  fs::create_directories(o.out);
  onboard::DatasetRig* rig = nullptr;
  onboard::Pipeline pipeline(config, [&](const onboard::SensorRings& rings) {
    auto made = std::make_unique<onboard::DatasetRig>(std::move(sequence), format + " " + o.dir,
                                                      config.camera.body_from_optical(),
                                                      o.selection, rings);
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"semap-dataset: a recorded dataset through the robot's perception and mapping"};
  app.require_subcommand(1);
  Options o;
  const auto add_common = [&](CLI::App* command) {
    command->add_option("DIR", o.dir, "the dataset's folder")
        ->required()
        ->check(CLI::ExistingDirectory);
    auto* card = command
                     ->add_option("--segmenter", o.segmenter_card,
                                  "model card of the network that labels the frames")
                     ->check(CLI::ExistingFile);
    auto* none = command->add_flag("--no-labels", o.no_labels, "geometry only: a 2-class map");
    card->excludes(none);
    command
        ->add_option("--map", o.map_config,
                     "YAML file with the robot's map: section (default: 5 cm cells, 5 m)")
        ->check(CLI::ExistingFile);
    command->add_option("--intrinsics", o.intrinsics,
                        "fx,fy,cx,cy in pixels (default: the dataset's, if it has them)");
    command
        ->add_option("--depth-scale", o.depth_scale,
                     "raw depth units per metre (default: 5000 TUM, 1000 Redwood)")
        ->check(CLI::PositiveNumber);
    command->add_option("--first", o.selection.first, "first frame (index)");
    command->add_option("--last", o.selection.last, "last frame (index)");
    command->add_option("--stride", o.selection.stride, "every n-th frame")
        ->check(CLI::PositiveNumber);
    command->add_option("--out", o.out, "output folder (default out/dataset)");
    command->add_option("--threads", o.threads, "map insert threads")->check(CLI::Range(1, 64));
  };
  auto* tum = app.add_subcommand("tum", "TUM RGB-D: rgb.txt, depth.txt, groundtruth.txt");
  auto* redwood = app.add_subcommand(
      "redwood", "Redwood / Open3D: color/, depth/, odometry.log, intrinsic JSON");
  add_common(tum);
  add_common(redwood);
  apps::add_kitti_raw_command(app);
  apps::add_kitti_semantic_command(app);
  CLI11_PARSE(app, argc, argv);
  // kitti-raw and semantickitti run as the parse's callbacks (a failure exits with its status).
  if (app.got_subcommand("kitti-raw") || app.got_subcommand("semantickitti")) return 0;
  if (o.segmenter_card.empty() && !o.no_labels) {
    std::cerr << "semap-dataset: give --segmenter CARD or --no-labels\n";
    return 2;
  }
  common::setup_logging("warn");
  try {
    return run(tum->parsed() ? "tum" : "redwood", o);
  } catch (const std::exception& e) {
    std::cerr << "\nsemap-dataset: " << e.what() << "\n";
    return 1;
  }
}
