#include "semap/sim/report.hpp"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "semap/estimation/geodesy.hpp"
#include "semap/mapping/semantic_map.hpp"
#include "semap/perception/palette_segmenter.hpp"

namespace semap::sim {

namespace {

constexpr std::uint64_t kSampleFrame = 100;  // the frame camera.png shows (or the last one)
constexpr double kPoseSamplePeriod = 0.1;    // seconds between trajectory points

using perception::kSimMapClasses;
using perception::kSimMapClassTable;

// Map class of each train id (kNoLabel for sky and the ids the world lacks).
std::array<std::uint16_t, 256> train_id_to_map_class() {
  std::array<std::uint16_t, 256> lut{};
  for (std::size_t id = 0; id < lut.size(); ++id) {
    lut[id] = perception::sim_map_class(static_cast<std::uint8_t>(id));
  }
  return lut;
}

// Cityscapes colour (BGR) of a train id; black for 255 and ids beyond the palette.
cv::Vec3b train_id_colour(std::uint8_t id) {
  static const auto palette = perception::cityscapes_palette();
  if (id >= palette.size()) return {0, 0, 0};
  const auto& rgb = palette[id].color;
  return {rgb[2], rgb[1], rgb[0]};
}

cv::Mat paint_train_ids(const cv::Mat& ids) {
  cv::Mat out(ids.size(), CV_8UC3);
  ids.forEach<std::uint8_t>([&](std::uint8_t id, const int* at) {
    out.at<cv::Vec3b>(at[0], at[1]) = train_id_colour(id);
  });
  return out;
}

cv::Mat paint_map_classes(const cv::Mat& classes) {
  cv::Mat out(classes.size(), CV_8UC3);
  classes.forEach<std::uint16_t>([&](std::uint16_t c, const int* at) {
    out.at<cv::Vec3b>(at[0], at[1]) = c > 0 && c < kSimMapClasses
                                          ? train_id_colour(kSimMapClassTable[c].train_id)
                                          : cv::Vec3b(0, 0, 0);
  });
  return out;
}

void put_text(cv::Mat& image, const std::string& text, cv::Point at, double scale = 0.6,
              cv::Scalar colour = {0, 0, 0}) {
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

void write_png(const std::filesystem::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) throw std::runtime_error("cannot write " + path.string());
}

std::string number(std::optional<double> v, int decimals = 4) {
  if (!v || !std::isfinite(*v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, *v);
  return buf;
}

// {"road": 0.98, ...} over map classes 1..K-1, null for those the truth never has.
std::string per_class(const mapping::ConfusionMatrix& confusion) {
  std::string out = "{";
  for (int c = 1; c < kSimMapClasses; ++c) {
    out += (c > 1 ? ", \"" : "\"") + std::string(kSimMapClassTable[c].name) +
           "\": " + number(confusion.iou_if_present(c));
  }
  return out + "}";
}

// Rows are true classes (free first), columns predicted classes then "no label".
std::string confusion_rows(const mapping::ConfusionMatrix& confusion) {
  std::string out = "[";
  for (int t = 0; t < kSimMapClasses; ++t) {
    out += t ? ", [" : "[";
    for (int p = 0; p <= kSimMapClasses; ++p) {
      out += (p ? ", " : "") + std::to_string(confusion.count(t, p));
    }
    out += "]";
  }
  return out + "]";
}

}  // namespace

Eigen::Vector3d sim_from_map(const SimRig& rig, const estimation::Geodetic& anchor) {
  return estimation::LocalEnu(rig.data().origin).to_enu(anchor);
}

std::optional<PoseVsTruth> pose_vs_truth(const SimRig& rig,
                                         const onboard::EstimationStageStats& s) {
  if (!s.initialised || !s.latest || !s.anchor) return std::nullopt;
  const auto truth = rig.truth_at(s.latest->stamp);
  if (!truth) return std::nullopt;
  return PoseVsTruth{s.latest->position + sim_from_map(rig, *s.anchor), truth->state.position,
                     s.latest->stamp};
}

SimReport::SimReport(const SimRig& rig, std::filesystem::path dir)
    : rig_(rig), dir_(std::move(dir)) {
  if (!dir_.empty()) std::filesystem::create_directories(dir_);
}

void LiveAccuracy::sample(const SimRig& rig, const onboard::EstimationStageStats& s) {
  const auto pose = pose_vs_truth(rig, s);
  if (!pose) return;
  if (!first_) first_ = pose->stamp;
  if (common::seconds_between(pose->stamp, *first_) < 10.0) return;  // settling
  const double e2 = (pose->estimate - pose->truth).squaredNorm();
  sum_sq_ += e2;
  max_ = std::max(max_, std::sqrt(e2));
  ++count_;
}

double LiveAccuracy::rmse() const { return std::sqrt(sum_sq_ / static_cast<double>(count_)); }

void SimReport::on_estimate(const onboard::EstimationStageStats& s) {
  accuracy_.sample(rig_, s);
  if (!dir_.empty()) sample_pose(s);
}

void SimReport::summary(std::vector<std::string>& lines) const {
  if (!accuracy_.any()) return;
  lines.push_back(
      fmt::format("pose vs truth    : position RMSE {:.3f} m, max {:.3f} m over {} checks",
                  accuracy_.rmse(), accuracy_.max(), accuracy_.count()));
}

std::filesystem::path SimReport::write(onboard::Pipeline& pipeline) const {
  RunFigures figures;
  const auto kind = pipeline.config().segmenter.kind;
  figures.segmenter = kind == onboard::SegmenterConfig::Kind::kDnn        ? "dnn"
                      : kind == onboard::SegmenterConfig::Kind::kGeometry ? "geometry"
                                                                          : "palette";
  if (accuracy_.any()) figures.pose_rmse_m = accuracy_.rmse();
  figures.frames_captured = rig_.camera().rendered();
  figures.frames_mapped = pipeline.mapping().scans;
  figures.latency_frame_to_map = pipeline.mapping_stage().latency().percentiles();
  figures.latency_phases = {{"delivered", rig_.camera().delivery_age().percentiles()}};
  for (auto& phase :
       onboard::latency_phases(pipeline.perception_stage(), pipeline.mapping_stage())) {
    figures.latency_phases.push_back(std::move(phase));
  }
  figures.ring_drops = pipeline.ring_drops();
  figures.cpu_cores_used = pipeline.cpu_cores();
  return write(figures, pipeline.map(), pipeline.estimation());
}

void SimReport::on_segmentation(std::uint32_t sequence, common::Stamp, const cv::Mat& bgr,
                                const perception::Segmentation& seg) {
  if (dir_.empty()) return;
  static const auto to_map_class = train_id_to_map_class();
  const auto truth = rig_.camera().true_labels(sequence);
  if (!truth || truth->size() != seg.labels.size()) return;  // no longer kept
  // Per (true, predicted) pair over the frame, then into the matrix: sky pixels are not
  // scored, pixels the segmenter left unlabelled count as misses.
  std::array<std::array<std::uint64_t, kSimMapClasses + 1>, kSimMapClasses> frame{};
  for (int v = 0; v < truth->rows; ++v) {
    const auto* t = truth->ptr<std::uint8_t>(v);
    const auto* p = seg.labels.ptr<std::uint16_t>(v);
    for (int u = 0; u < truth->cols; ++u) {
      const std::uint16_t c = to_map_class[t[u]];
      if (c >= kSimMapClasses) continue;
      ++frame[c][std::min<std::uint16_t>(p[u], kSimMapClasses)];
    }
  }
  std::lock_guard lock(mutex_);
  for (std::uint16_t c = 0; c < kSimMapClasses; ++c) {
    for (std::uint16_t j = 0; j <= kSimMapClasses; ++j) {
      if (frame[c][j]) pixels_.add(c, j, frame[c][j]);
    }
  }
  if (++frames_observed_ <= kSampleFrame) {
    sample_ = Sample{bgr.clone(), seg.labels.clone(), truth->clone()};
  }
}

void SimReport::sample_pose(const onboard::EstimationStageStats& s) {
  const auto pair = pose_vs_truth(rig_, s);
  if (!pair) return;
  if (last_pose_ && common::seconds_between(pair->stamp, *last_pose_) < kPoseSamplePeriod) return;
  last_pose_ = pair->stamp;
  track_.emplace_back(pair->truth.head<2>(), pair->estimate.head<2>());
}

mapping::ConfusionMatrix SimReport::map_confusion(
    const mapping::SemanticMap& map, const onboard::EstimationStageStats& final) const {
  mapping::ConfusionMatrix confusion(kSimMapClasses);
  if (!final.anchor) return confusion;
  const Eigen::Vector3f map_to_sim = sim_from_map(rig_, *final.anchor).cast<float>();
  const auto& params = map.params();
  // A cell is on a surface when the surface passes through it: within its half-diagonal.
  const auto tolerance = static_cast<float>(params.resolution * std::sqrt(3.0) / 2.0);
  map.for_each_cell([&](const Eigen::Vector3f& centre, const common::CellPosterior& cell) {
    if (cell.state(params.unknown_variance) != common::CellState::kOccupied) return;
    confusion.add(rig_.world().class_at(centre + map_to_sim, tolerance),
                  static_cast<std::uint16_t>(cell.argmax()));
  });
  return confusion;
}

void SimReport::write_camera_png() const {
  std::lock_guard lock(mutex_);
  if (!sample_) return;
  const int w = sample_->bgr.cols, h = sample_->bgr.rows;
  constexpr int kTitle = 30, kLegend = 34;
  cv::Mat out(h + kTitle + kLegend, 3 * w, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Mat panels[] = {sample_->bgr, paint_map_classes(sample_->predicted),
                            paint_train_ids(sample_->truth)};
  const char* titles[] = {"camera (what the segmenter saw)", "segmenter output", "ground truth"};
  for (int i = 0; i < 3; ++i) {
    panels[i].copyTo(out(cv::Rect(i * w, kTitle, w, h)));
    put_text(out, titles[i], {i * w + 8, kTitle - 9});
  }
  // Legend: the map classes, sky (never mapped) and "no label" in black.
  std::vector<std::pair<std::string, cv::Vec3b>> entries;
  for (int c = 1; c < kSimMapClasses; ++c) {
    entries.emplace_back(kSimMapClassTable[c].name, train_id_colour(kSimMapClassTable[c].train_id));
  }
  entries.emplace_back("sky", train_id_colour(perception::sim_train_id::kSky));
  entries.emplace_back("no label", cv::Vec3b(0, 0, 0));
  int x = 8;
  const int y = h + kTitle + 8;
  for (const auto& [name, colour] : entries) {
    cv::rectangle(out, cv::Rect(x, y, 18, 18), cv::Scalar(colour[0], colour[1], colour[2]),
                  cv::FILLED);
    cv::rectangle(out, cv::Rect(x, y, 18, 18), cv::Scalar(0, 0, 0));
    put_text(out, name, {x + 24, y + 15});
    int baseline = 0;
    x += 24 + cv::getTextSize(name, cv::FONT_HERSHEY_SIMPLEX, 0.6, 1, &baseline).width + 24;
  }
  write_png(dir_ / "camera.png", out);
}

void SimReport::write_trajectory_png(std::optional<double> rmse) const {
  if (track_.empty()) return;
  Eigen::AlignedBox2d box;
  for (const auto& [truth, estimate] : track_) {
    box.extend(truth);
    box.extend(estimate);
  }
  box.min() -= Eigen::Vector2d::Constant(5.0);
  box.max() += Eigen::Vector2d::Constant(5.0);
  constexpr int kBorder = 60, kHeader = 70, kMinWidth = 760;
  const double scale = 900.0 / box.sizes().maxCoeff();  // pixels per metre
  // Wide enough for the legend.
  const double widen = std::max(0.0, kMinWidth / scale - box.sizes().x()) / 2.0;
  box.min().x() -= widen;
  box.max().x() += widen;
  const int width = static_cast<int>(box.sizes().x() * scale) + 2 * kBorder;
  const int height = static_cast<int>(box.sizes().y() * scale) + kHeader + kBorder;
  cv::Mat out(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const auto pixel = [&](const Eigen::Vector2d& p) {  // north up
    return cv::Point(kBorder + static_cast<int>((p.x() - box.min().x()) * scale),
                     height - kBorder - static_cast<int>((p.y() - box.min().y()) * scale));
  };
  // A metres grid of at most ~12 lines along the longer side.
  double step = 1.0;
  for (const double s : {1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0}) {
    step = s;
    if (box.sizes().maxCoeff() / s <= 12.0) break;
  }
  const cv::Scalar grid(220, 220, 220), label(90, 90, 90);
  for (double x = std::ceil(box.min().x() / step) * step; x <= box.max().x(); x += step) {
    const int px = pixel({x, 0.0}).x;
    cv::line(out, {px, kHeader}, {px, height - kBorder}, grid);
    put_text(out, number(x, 0), {px - 10, height - kBorder + 20}, 0.45, label);
  }
  for (double y = std::ceil(box.min().y() / step) * step; y <= box.max().y(); y += step) {
    const int py = pixel({0.0, y}).y;
    cv::line(out, {kBorder, py}, {width - kBorder, py}, grid);
    put_text(out, number(y, 0), {8, py + 5}, 0.45, label);
  }
  std::vector<cv::Point> truth, estimate;
  for (const auto& [t, e] : track_) {
    truth.push_back(pixel(t));
    estimate.push_back(pixel(e));
  }
  const cv::Scalar truth_colour(40, 150, 40), estimate_colour(30, 30, 220);
  cv::polylines(out, truth, false, truth_colour, 3, cv::LINE_AA);
  cv::polylines(out, estimate, false, estimate_colour, 1, cv::LINE_AA);
  put_text(out, "truth (simulator)", {kBorder, 26}, 0.6, truth_colour);
  put_text(out, "estimate (InEKF: IMU + GNSS)", {kBorder + 220, 26}, 0.6, estimate_colour);
  put_text(out,
           "x east, y north in metres, grid " + number(step, 0) + " m; position RMSE " +
               (rmse ? number(rmse, 3) + " m" : std::string("n/a")),
           {kBorder, 54}, 0.55, label);
  write_png(dir_ / "trajectory.png", out);
}

void SimReport::write_truth_csv(const onboard::EstimationStageStats& final) const {
  if (!final.anchor) return;
  const Eigen::Vector3d map_to_sim = sim_from_map(rig_, *final.anchor);
  std::ofstream out(dir_ / "truth.csv");
  out << "stamp_s,x,y,z\n";
  char line[128];
  for (const auto& t : rig_.data().truth) {
    const std::int64_t ns = rig_.started_at().ns + t.stamp.ns;
    const Eigen::Vector3d p = t.state.position - map_to_sim;
    std::snprintf(line, sizeof line, "%" PRId64 ".%09" PRId64 ",%.6f,%.6f,%.6f\n",
                  ns / 1'000'000'000, ns % 1'000'000'000, p.x(), p.y(), p.z());
    out << line;
  }
}

std::filesystem::path SimReport::write(const RunFigures& run, const mapping::SemanticMap& map,
                                       const onboard::EstimationStageStats& final) const {
  write_camera_png();
  write_trajectory_png(run.pose_rmse_m);
  write_truth_csv(final);
  const mapping::ConfusionMatrix cells = map_confusion(map, final);
  const mapping::ConfusionMatrix pixels = [&] {
    std::lock_guard lock(mutex_);
    return pixels_;
  }();
  std::ostringstream drops;
  for (std::size_t i = 0; i < run.ring_drops.size(); ++i) {
    drops << (i ? ", \"" : "\"") << run.ring_drops[i].first << "\": " << run.ring_drops[i].second;
  }
  const auto& latency = run.latency_frame_to_map;
  const bool have_latency = latency.count > 0;
  std::ostringstream phases;
  for (const auto& [name, ms] : run.latency_phases) {
    if (ms.count == 0) continue;
    phases << (phases.tellp() > 0 ? ",\n    \"" : "\n    \"") << name
           << "\": {\"p50\": " << number(ms.p50_ms, 1) << ", \"p99\": " << number(ms.p99_ms, 1)
           << ", \"max\": " << number(ms.max_ms, 1) << ", \"count\": " << ms.count << "}";
  }
  // One key per line, the last one without a comma: scripts/demo appends "listener".
  std::ostringstream json;
  json << "{\n"
       << "  \"segmenter\": \"" << run.segmenter << "\",\n"
       << "  \"pose_rmse_m\": " << number(run.pose_rmse_m, 3) << ",\n"
       << "  \"segmentation_miou\": " << number(pixels.mean_iou_of_present(1)) << ",\n"
       << "  \"segmentation_iou_per_class\": " << per_class(pixels) << ",\n"
       << "  \"map_miou\": " << number(cells.mean_iou_of_present(1)) << ",\n"
       << "  \"map_iou_per_class\": " << per_class(cells) << ",\n"
       << "  \"map_miou_surface_cells\": "
       << number(cells.without_true_class(0).mean_iou_of_present(1)) << ",\n"
       << "  \"map_cells\": {\"occupied\": " << cells.total()
       << ", \"off_surface\": " << cells.truth_count(0) << "},\n"
       << "  \"map_confusion_truth_by_predicted\": " << confusion_rows(cells) << ",\n"
       << "  \"frames_captured\": " << run.frames_captured << ",\n"
       << "  \"frames_mapped\": " << run.frames_mapped << ",\n"
       << "  \"latency_frame_to_map_ms\": {\"p50\": "
       << number(have_latency ? std::optional<double>(latency.p50_ms) : std::nullopt, 1)
       << ", \"p99\": "
       << number(have_latency ? std::optional<double>(latency.p99_ms) : std::nullopt, 1) << "},\n"
       << "  \"latency_phases_ms\": {" << phases.str() << "},\n"
       << "  \"ring_drops\": {" << drops.str() << "},\n"
       << "  \"cpu_cores_used\": " << number(run.cpu_cores_used, 2) << "\n"
       << "}\n";
  const auto path = dir_ / "summary.json";
  std::ofstream out(path);
  out << json.str();
  if (!out) throw std::runtime_error("cannot write " + path.string());
  return path;
}

}  // namespace semap::sim
