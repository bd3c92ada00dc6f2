// Prints the perception figures of issue 14 for 640x480 frames on this machine: per-stage
// medians and 90th percentiles (decode, segment, depth -> points, posing, map insert), then a
// steady-state run of the real PerceptionStage and MappingStage on their own threads, fed at
// 15 Hz with YUYV colour and aligned Z16 depth while a pose thread drives a circle.
//
// With --model-card CARD it measures networks instead (issue 31): for the shipped semap-seg
// card (the baseline, --baseline) and then CARD, on real RGB-D frames (the five Redwood frames
// of ../shared/data/real/redwood, MJPEG colour and Z16 depth in millimetres; the simulated
// scene where they are absent): the network's forward pass on an image resized to the card's
// input, the whole segment() of a 640x480 frame (p50/p99 over --frames), and the 15 Hz steady
// state of the same stages with the card's segmenter, then a table of both.
// --carry-labels runs the steady state with the network on its own thread and labels carried
// between its segmentations (perception.carry_labels; --segment-hz: perception.segment_hz).
//
// The last line is parsed by scripts (in --model-card mode: CARD's steady state):
//   steady state: F frames/s mapped, latency p50 A ms p99 B ms, cpu C cores
#include <tbb/task_arena.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bench_inputs.hpp"
#include "semap/common/process_usage.hpp"
#include "semap/drivers/frame_convert.hpp"
#include "semap/drivers/jpeg_decoder.hpp"
#include "semap/mapping/cloud_transform.hpp"
#include "semap/onboard/mapping_stage.hpp"
#include "semap/onboard/perception_stage.hpp"
#include "semap/onboard/segmenter_factory.hpp"
#include "semap/onboard/shared_pose_history.hpp"
#include "semap/perception/depth_cloud.hpp"
#include "semap/perception/dnn_segmenter.hpp"
#include "semap/perception/palette_segmenter.hpp"
#include "semap/perception/sim_classes.hpp"

namespace {

namespace bench = semap::bench;
namespace common = semap::common;
namespace onboard = semap::onboard;
namespace perception = semap::perception;
using Clock = std::chrono::steady_clock;

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr double kCameraHz = 15.0;
constexpr double kPoseHz = 200.0;
constexpr int kMapClasses = perception::kSimMapClasses;

struct Options {
  double seconds = 20.0;
  int frames = 30;
  int threads = 2;     // the map's TBB threads
  int cv_threads = 1;  // OpenCV's (the model card's threads)
  int stride = 2;      // every 2nd pixel: finer than the map's 0.2 m at 640x480 still
  std::string infer = "320x240";
  std::filesystem::path model_card;  // a trained network instead of the synthetic one
  std::filesystem::path baseline = SEMAP_SOURCE_DIR "/models/semap-seg.yaml";
  std::filesystem::path redwood = SEMAP_SHARED_DATA_DIR "/real/redwood";
  bool carry_labels = false;
  double segment_hz = 0.0;
};

void row(const std::string& what, const bench::Spread& s) {
  std::printf("  %-60s p50 %7.2f ms  p90 %7.2f ms\n", what.c_str(), s.p50, s.p90);
}

// A folder for the model card and network, removed at exit.
struct TempDir {
  std::filesystem::path path = std::filesystem::temp_directory_path() /
                               ("semap_perception_bench_" + std::to_string(::getpid()));
  TempDir() { std::filesystem::create_directories(path); }
  ~TempDir() { std::filesystem::remove_all(path); }
};

void per_stage(const Options& o, const onboard::OnboardConfig& config,
               const bench::SceneImages& scene, const bench::BenchModel& model) {
  const int n = o.frames;
  std::printf("per frame (%d frames each):\n", n);
  semap::drivers::JpegDecoder jpeg;
  cv::Mat image;
  row("decode YUYV -> BGR (drivers::to_mat)",
      bench::time_ms(n, [&](int) { image = semap::drivers::to_mat(scene.yuyv, jpeg); }));
  common::ImageFrame mjpeg = scene.yuyv;
  mjpeg.format = common::PixelFormat::kMjpeg;
  cv::imencode(".jpg", scene.camera_bgr, mjpeg.data, {cv::IMWRITE_JPEG_QUALITY, 90});
  const std::string jpeg_what =
      "decode MJPEG -> BGR (q90, " + std::to_string(mjpeg.data.size() / 1024) + " KiB)";
  row(jpeg_what, bench::time_ms(n, [&](int) { image = semap::drivers::to_mat(mjpeg, jpeg); }));

  perception::DnnSegmenter onnx(perception::load_model_card(model.card));
  const cv::Mat bgr = semap::drivers::to_mat(scene.yuyv, jpeg);
  perception::Segmentation seg;
  char what[160];
  std::snprintf(what, sizeof what, "segment ONNX at %s (%.2f GFLOP, %d -> %d classes)",
                o.infer.c_str(), model.gflops, model.classes, kMapClasses);
  row(what, bench::time_ms(n, [&](int) { seg = onnx.segment(bgr); }));
  perception::PaletteSegmenter palette(
      perception::cityscapes_palette(perception::sim_cityscapes_mapping()), kMapClasses);
  perception::Segmentation palette_seg;
  row("segment palette (Cityscapes colours)",
      bench::time_ms(n, [&](int) { palette_seg = palette.segment(scene.label_bgr); }));

  const cv::Mat z16 = semap::drivers::to_mat(scene.z16, jpeg);
  const Eigen::Isometry3f body_from_optical = config.camera.body_from_optical();
  common::LabeledCloud clouds[2];
  for (const int stride : {1, 2}) {
    perception::PointOptions points = config.depth.points;
    points.stride = stride;
    perception::DropCounts drops;
    common::LabeledCloud& cloud = clouds[stride - 1];
    const auto s = bench::time_ms(n, [&](int) {
      cloud =
          perception::cloud_from_depth(perception::depth_metres(z16, 0.001f), seg,
                                       config.camera.intrinsics, body_from_optical, points, drops);
    });
    row("depth -> points, stride " + std::to_string(stride) + " (" + std::to_string(cloud.size()) +
            " points)",
        s);
  }

  onboard::SharedPoseHistory poses(4096);
  std::vector<semap::estimation::StampedPose> trajectory;
  for (int i = 0; i <= 2000; ++i) {
    trajectory.push_back(bench::circle_pose(i / kPoseHz, common::Stamp::from_seconds(i / kPoseHz)));
  }
  poses.append(trajectory);
  common::LabeledCloud world;
  row("posing: SharedPoseHistory::at + to world (stride 1)", bench::time_ms(n, [&](int i) {
        const auto lookup = poses.at(common::Stamp::from_seconds((i + 0.37) / kCameraHz));
        world = semap::mapping::transform_cloud(clouds[0], lookup.pose.world_from_body());
      }));

  tbb::task_arena arena(o.threads);
  for (const int stride : {1, 2}) {
    semap::mapping::SemanticMap map(config.map.params);
    const auto s = bench::time_ms(n, [&](int i) {
      const double t = i / kCameraHz;
      common::LabeledCloud cloud = semap::mapping::transform_cloud(
          clouds[stride - 1], bench::circle_pose(t, {}).world_from_body());
      arena.execute([&] { map.insert(cloud, cloud.origin); });
    });
    const auto stats = map.stats();
    row("map insert S-BKI, stride " + std::to_string(stride) + ", " + std::to_string(o.threads) +
            " threads (" + std::to_string(stats.blocks) + " blocks)",
        s);
  }
}

struct SteadyState {
  double mapped_hz = 0, cpu_cores = 0;
  common::LatencyPercentiles latency;
  std::uint64_t frames = 0, clouds = 0, skipped = 0;  // the perception stage's
};

// Colour and depth frames as the drivers deliver them; the steady state pushes them in turn.
struct FramePairs {
  std::vector<common::ImageFrame> colour, depth;
};

SteadyState steady_state(const Options& o, const onboard::OnboardConfig& config,
                         const FramePairs& input, const std::filesystem::path& card) {
  using common::OverflowPolicy;
  common::SpscRing<common::ImageFrame> colour_ring(config.camera.ring, OverflowPolicy::kDropOldest);
  common::SpscRing<common::ImageFrame> depth_ring(config.depth.ring, OverflowPolicy::kDropOldest);
  common::SpscRing<common::LabeledCloud> cloud_ring(config.depth.ring, OverflowPolicy::kDropOldest);
  onboard::SharedPoseHistory poses(config.estimator.history);
  onboard::SegmenterConfig seg;
  seg.kind = onboard::SegmenterConfig::Kind::kDnn;
  seg.model_card = card;
  onboard::PerceptionStage perception(
      config.camera, config.depth, onboard::make_segmenter(seg, config.map.params.num_classes),
      colour_ring, &depth_ring, nullptr, poses, cloud_ring, 0.0, config.perception);
  onboard::MappingStage mapping(config.map, cloud_ring, nullptr, {});

  // The estimation stage's part: filter poses at 200 Hz, stamped now.
  const common::Stamp t0 = common::Stamp::now();
  std::jthread pose_thread([&](std::stop_token stop) {
    auto next = Clock::now();
    while (!stop.stop_requested()) {
      const common::Stamp now = common::Stamp::now();
      const auto pose = bench::circle_pose(common::seconds_between(now, t0), now);
      poses.append({&pose, 1});
      next += std::chrono::microseconds(static_cast<int>(1e6 / kPoseHz));
      std::this_thread::sleep_until(next);
    }
  });
  mapping.start();
  perception.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));

  const double cpu0 = semap::common::process_cpu_seconds();
  const auto start = Clock::now();
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / kCameraHz));
  const auto frames = static_cast<std::uint32_t>(o.seconds * kCameraHz);
  for (std::uint32_t i = 0; i < frames; ++i) {
    std::this_thread::sleep_until(start + i * period);
    common::ImageFrame colour = input.colour[i % input.colour.size()];
    common::ImageFrame depth = input.depth[i % input.depth.size()];
    colour.stamp = depth.stamp = common::Stamp::now();
    colour.sequence = depth.sequence = i;
    colour_ring.try_push(std::move(colour));
    depth_ring.try_push(std::move(depth));
  }
  std::this_thread::sleep_until(start + frames * period);
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  const double cpu = semap::common::process_cpu_seconds() - cpu0;
  const auto m = mapping.stats();
  perception.stop();
  mapping.stop();
  pose_thread.request_stop();
  const auto p = perception.stats();

  const auto drops = [](const auto& ring) { return ring.counters().drops(); };
  // Frames passed over or without a depth partner never reach the segmenter.
  const std::uint64_t segmented = config.perception.carry_labels
                                      ? p.segmented
                                      : p.frames - std::min(p.frames, p.skipped + p.unpaired);
  const std::uint64_t ring_drops = drops(colour_ring) + drops(cloud_ring);
  std::printf("steady state over %.1f s (%u frames pushed at %.0f Hz, stride %d):\n", wall, frames,
              kCameraHz, config.depth.points.stride);
  std::printf(
      "  perception: %lu frames, %lu clouds, segment mean %.1f ms max %.1f ms, %.0f "
      "points/cloud, frame -> posed cloud p50 %.1f ms p99 %.1f ms\n",
      p.frames, p.clouds,
      segmented ? 1e3 * p.segment_seconds_total / static_cast<double>(segmented) : 0.0,
      1e3 * p.segment_seconds_max,
      p.clouds ? static_cast<double>(p.points) / static_cast<double>(p.clouds) : 0.0,
      perception.latency().percentiles().p50_ms, perception.latency().percentiles().p99_ms);
  if (config.perception.carry_labels) {
    std::printf(
        "  network on its own thread: %lu frames segmented (%.1f Hz), %lu clouds with carried "
        "labels, %lu frames with labels too old, %lu failures, %lu pixels occluded\n",
        p.segmented, static_cast<double>(p.segmented) / wall, p.carried, p.labels_too_old,
        p.segment_failures, p.dropped.occluded);
  }
  std::printf("  mapping: %lu scans, insert mean %.1f ms max %.1f ms, map %zu blocks %zu cells\n",
              m.scans, m.scans ? 1e3 * m.insert_seconds_total / static_cast<double>(m.scans) : 0.0,
              1e3 * m.insert_seconds_max, m.map.blocks, m.map.cells);
  std::printf("  drops: %lu (ring %lu, skipped %lu, unpaired %lu, without pose %lu, bad %lu)\n",
              ring_drops + p.skipped + p.unpaired + p.without_pose + p.bad_frames, ring_drops,
              p.skipped, p.unpaired, p.without_pose, p.bad_frames);
  return {static_cast<double>(m.scans) / wall,
          cpu / wall,
          mapping.latency().percentiles(),
          p.frames,
          p.clouds,
          p.skipped};
}

void print_steady_state(const SteadyState& s) {
  std::printf(
      "steady state: %.1f frames/s mapped, latency p50 %.0f ms p99 %.0f ms, cpu %.2f cores\n",
      s.mapped_hz, s.latency.p50_ms, s.latency.p99_ms, s.cpu_cores);
}

// Real RGB-D frames for --model-card: the Redwood frames (colour/*.jpg as MJPEG frames, depth/
// *.png, uint16 millimetres), with their camera's intrinsics. Empty when absent or unreadable.
struct RealFrames {
  FramePairs pairs;
  std::vector<cv::Mat> bgr;  // the colour frames decoded, for the per-frame figures
  perception::PinholeIntrinsics intrinsics;
  float depth_scale = 0.001f;
  std::string source;
};

std::optional<RealFrames> redwood_frames(const std::filesystem::path& dir) {
  std::error_code ec;
  std::vector<std::filesystem::path> colours;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "color", ec)) {
    if (entry.path().extension() == ".jpg") colours.push_back(entry.path());
  }
  if (ec || colours.empty()) return std::nullopt;
  std::sort(colours.begin(), colours.end());
  RealFrames real;
  for (const auto& colour_file : colours) {
    const auto depth_file = dir / "depth" / colour_file.filename().replace_extension(".png");
    const cv::Mat bgr = cv::imread(colour_file.string(), cv::IMREAD_COLOR);
    const cv::Mat z16 = cv::imread(depth_file.string(), cv::IMREAD_UNCHANGED);
    if (bgr.empty() || z16.type() != CV_16UC1 || bgr.size() != z16.size() || bgr.cols != kWidth ||
        bgr.rows != kHeight) {
      return std::nullopt;
    }
    common::ImageFrame colour;
    colour.format = common::PixelFormat::kMjpeg;
    colour.width = static_cast<std::uint32_t>(bgr.cols);
    colour.height = static_cast<std::uint32_t>(bgr.rows);
    std::ifstream in(colour_file, std::ios::binary);
    colour.data.assign(std::istreambuf_iterator<char>(in), {});
    common::ImageFrame depth;
    depth.format = common::PixelFormat::kZ16;
    depth.width = colour.width;
    depth.height = colour.height;
    depth.stride = 2 * depth.width;
    const cv::Mat packed = z16.clone();
    depth.data.assign(packed.datastart, packed.dataend);
    real.pairs.colour.push_back(std::move(colour));
    real.pairs.depth.push_back(std::move(depth));
    real.bgr.push_back(bgr);
  }
  // camera_primesense.json: Open3D's PrimeSense defaults.
  real.intrinsics = {kWidth, kHeight, 525.0f, 525.0f, 319.5f, 239.5f};
  real.source = "Redwood " + dir.string() + " (" + std::to_string(real.bgr.size()) +
                " RGB-D frames, MJPEG + Z16 mm)";
  return real;
}

struct CardFigures {
  std::string name, input;
  double load = 0.0;  // 1-minute load average when the card's run began
  bench::Spread forward, segment;
  SteadyState steady;
};

// One card: its forward pass and segment() per frame, then the 15 Hz steady state.
CardFigures measure_card(const Options& o, onboard::OnboardConfig config, const RealFrames& real,
                         const std::filesystem::path& card_file) {
  const auto card = perception::load_model_card(card_file);
  CardFigures f;
  f.name = card_file.filename().string();
  f.input = std::to_string(card.input_width) + "x" + std::to_string(card.input_height);
  double load[3] = {};
  getloadavg(load, 3);
  f.load = load[0];
  std::printf(
      "\n%s: %s network (%s), input %s, %zu classes -> map K = %d, %d OpenCV threads, "
      "load %.2f %.2f %.2f\n",
      card_file.c_str(), std::string(perception::format_name(card.format)).c_str(),
      card.model_file.filename().c_str(), f.input.c_str(), card.classes.size(),
      card.num_map_classes, card.threads, load[0], load[1], load[2]);
  perception::DnnSegmenter segmenter(card);  // reads the network, runs it once
  std::vector<cv::Mat> resized;
  for (const cv::Mat& bgr : real.bgr) {
    cv::Mat r;
    cv::resize(bgr, r, {card.input_width, card.input_height}, 0, 0, cv::INTER_AREA);
    resized.push_back(r);
  }
  const auto n = resized.size();
  f.forward = bench::time_ms(o.frames, [&](int i) { segmenter.forward(resized[i % n]); });
  perception::Segmentation seg;
  f.segment = bench::time_ms(o.frames, [&](int i) { seg = segmenter.segment(real.bgr[i % n]); });
  std::printf("  forward at %-9s (network only, %d frames)          p50 %7.1f ms  p99 %7.1f ms\n",
              f.input.c_str(), o.frames, f.forward.p50, f.forward.p99);
  std::printf("  segment %dx%d (resize, forward, classes, labels)   p50 %7.1f ms  p99 %7.1f ms\n",
              kWidth, kHeight, f.segment.p50, f.segment.p99);

  config.map.params.num_classes = card.num_map_classes;
  f.steady = steady_state(o, config, real.pairs, card_file);
  print_steady_state(f.steady);
  return f;
}

int model_cards(const Options& o, onboard::OnboardConfig config, const bench::SceneImages& scene) {
  std::optional<RealFrames> real = redwood_frames(o.redwood);
  if (real) {
    config.camera.intrinsics = real->intrinsics;
    config.depth.depth_scale = real->depth_scale;
  } else {
    std::printf(
        "%s: no Redwood frames (../shared/data/real, see its README.md); the simulated "
        "scene instead\n",
        o.redwood.c_str());
    real.emplace();
    real->pairs.colour = {scene.yuyv};
    real->pairs.depth = {scene.z16};
    real->bgr = {scene.camera_bgr};
    real->depth_scale = config.depth.depth_scale;
    real->source = "the simulated scene (YUYV + Z16)";
  }
  std::printf(
      "frames: %s; steady state %.0f s at %.0f Hz per card, depth stride %d, map "
      "threads %d\n",
      real->source.c_str(), o.seconds, kCameraHz, o.stride, o.threads);
  std::vector<std::filesystem::path> cards;
  std::error_code ec;
  if (!o.baseline.empty() && !std::filesystem::equivalent(o.baseline, o.model_card, ec)) {
    cards.push_back(o.baseline);
  }
  cards.push_back(o.model_card);
  std::vector<CardFigures> figures;
  for (const auto& card : cards) figures.push_back(measure_card(o, config, *real, card));

  std::printf(
      "\n| card | input | load | forward p50 / p99 | segment 640x480 p50 / p99 | "
      "15 Hz: frames/s mapped | latency p50 / p99 | CPU cores |\n"
      "|---|---|---|---|---|---|---|---|\n");
  for (const auto& f : figures) {
    std::printf(
        "| %s | %s | %.2f | %.1f / %.1f ms | %.1f / %.1f ms | %.1f | %.0f / %.0f ms | "
        "%.2f |\n",
        f.name.c_str(), f.input.c_str(), f.load, f.forward.p50, f.forward.p99, f.segment.p50,
        f.segment.p99, f.steady.mapped_hz, f.steady.latency.p50_ms, f.steady.latency.p99_ms,
        f.steady.cpu_cores);
  }
  print_steady_state(figures.back().steady);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"perception_bench: camera -> segmentation -> points -> S-BKI map, 640x480"};
  app.add_option("--seconds", o.seconds, "steady-state run length")->check(CLI::PositiveNumber);
  app.add_option("--frames", o.frames, "frames per per-stage figure")->check(CLI::Range(1, 100000));
  app.add_option("--threads", o.threads, "TBB threads of the map insert")->check(CLI::Range(1, 64));
  app.add_option("--cv-threads", o.cv_threads, "OpenCV threads (model card `threads`)")
      ->check(CLI::Range(1, 64));
  app.add_option("--stride", o.stride, "pixel stride of depth -> points in the steady state")
      ->check(CLI::Range(1, 16));
  app.add_option("--infer", o.infer, "network input size WxH of the synthetic network");
  app.add_option("--model-card", o.model_card,
                 "measure this network on real frames against the baseline card")
      ->check(CLI::ExistingFile);
  app.add_option("--baseline", o.baseline, "the card measured first with --model-card (\"\": none)")
      ->capture_default_str();
  app.add_option("--redwood", o.redwood, "Redwood RGB-D frames for --model-card")
      ->capture_default_str();
  app.add_flag("--carry-labels", o.carry_labels,
               "steady state: the network on its own thread, labels carried between");
  app.add_option("--segment-hz", o.segment_hz, "with --carry-labels: at most this rate (0: any)")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);
  if (!o.model_card.empty() && app.count("--seconds") == 0) o.seconds = 10.0;
  int infer_w = 0, infer_h = 0;
  if (std::sscanf(o.infer.c_str(), "%dx%d", &infer_w, &infer_h) != 2 || infer_w < 8 ||
      infer_h < 8) {
    std::fprintf(stderr, "--infer: expected WxH, got '%s'\n", o.infer.c_str());
    return 2;
  }

  onboard::OnboardConfig config;
  config.camera.driver.width = kWidth;
  config.camera.driver.height = kHeight;
  config.camera.driver.fps = kCameraHz;
  config.camera.intrinsics =
      perception::PinholeIntrinsics::from_fov(kWidth, kHeight, std::numbers::pi_v<float> / 2);
  config.depth.points.stride = o.stride;
  config.depth.points.max_range = 20.0f;
  config.map.params.resolution = 0.2f;  // config/sim.yaml's map
  config.map.params.block_depth = 3;
  config.map.params.num_classes = kMapClasses;
  config.map.params.ell = 0.5f;
  config.map.params.free_res = 1.0f;
  config.map.params.ds_res = 0.2f;
  config.map.params.max_range = 20.0f;
  config.map.threads = o.threads;
  config.perception.carry_labels = o.carry_labels;
  config.perception.segment_hz = o.segment_hz;
  // The steady state cycles still frames while its poses drive a circle: the depth of a carried
  // pixel never agrees with the segmented frame's, and the occlusion test would drop them all.
  // Opened, each cloud keeps the points it would have had, and the cost is the one measured.
  config.perception.carry.depth_tolerance_m = 1e3f;

  const TempDir dir;
  const auto scene = bench::render_scene(config.camera, config.depth.depth_scale);
  double load[3] = {};
  getloadavg(load, 3);
  if (!o.model_card.empty()) {
    std::printf("perception_bench --model-card: %dx%d frames, load %.2f %.2f %.2f\n", kWidth,
                kHeight, load[0], load[1], load[2]);
    return model_cards(o, config, scene);
  }
  const bench::BenchModel model =
      bench::write_bench_model(dir.path, infer_w, infer_h, kMapClasses, o.cv_threads);
  std::printf("perception_bench: %dx%d, map threads %d, OpenCV threads %d, load %.2f %.2f %.2f\n",
              kWidth, kHeight, o.threads, o.cv_threads, load[0], load[1], load[2]);
  per_stage(o, config, scene, model);
  print_steady_state(steady_state(o, config, {{scene.yuyv}, {scene.z16}}, model.card));
  return 0;
}
