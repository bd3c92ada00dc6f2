// semap-render-dataset: frames of the simulated camera with their true classes, for training
// and validating a segmentation network (scripts/train-segmenter). Each world seed simulates a
// drive, builds the street world around it and renders frames from poses along the drive,
// with the camera mount jittered so the network does not learn one horizon line.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "semap/perception/palette_segmenter.hpp"
#include "semap/perception/sim_classes.hpp"
#include "semap/sim/camera.hpp"
#include "semap/sim/drive_simulator.hpp"
#include "semap/sim/world.hpp"

namespace {

using namespace semap;

// The network's output classes, in channel order: the world's map classes, then sky.
constexpr std::array<std::uint8_t, 8> kModelTrainIds = {
    perception::sim_train_id::kRoad,       perception::sim_train_id::kSidewalk,
    perception::sim_train_id::kBuilding,   perception::sim_train_id::kPole,
    perception::sim_train_id::kVegetation, perception::sim_train_id::kTerrain,
    perception::sim_train_id::kCar,        perception::sim_train_id::kSky};

std::array<std::uint8_t, 256> model_class_of_train_id() {
  std::array<std::uint8_t, 256> lut;
  lut.fill(255);  // ignored in training
  for (std::size_t m = 0; m < kModelTrainIds.size(); ++m) {
    lut[kModelTrainIds[m]] = static_cast<std::uint8_t>(m);
  }
  return lut;
}

struct Settings {
  std::filesystem::path out;
  int first_seed = 1000;
  int worlds = 8;
  int frames_per_world = 40;
  int width = 320;
  int height = 240;
};

estimation::DriveData drive(int seed) {
  sim::SimulatorConfig sim;
  sim.scenario = seed % 2 == 0 ? sim::Scenario::kFigureEight : sim::Scenario::kCar;
  sim.duration_s = 60.0;
  sim.speed_m_s = 5.0;
  sim.imu_rate_hz = 50.0;
  sim.initial_yaw_rad = 0.7 * seed;
  sim.seed = static_cast<std::uint64_t>(seed);
  return sim::simulate(sim);
}

// Renders `frames` frames of world `seed` into `folder`, numbered from `index`.
int render_world(const Settings& s, int seed, const std::filesystem::path& folder, int index) {
  const auto data = drive(seed);
  std::vector<Eigen::Vector3d> path;
  for (const auto& t : data.truth) path.push_back(t.state.position);
  sim::SimWorldOptions world_options;
  world_options.seed = static_cast<std::uint64_t>(seed);
  const sim::SimWorld world(path, world_options);
  sim::SimCameraOptions camera_options;
  camera_options.seed = static_cast<std::uint64_t>(seed);
  const sim::SimCamera camera(camera_options);
  const auto lut = model_class_of_train_id();
  std::mt19937 rng(static_cast<std::uint32_t>(seed));
  std::uniform_int_distribution<std::size_t> pick(data.truth.size() / 20, data.truth.size() - 1);
  std::uniform_real_distribution<float> jitter(-1.0f, 1.0f);
  for (int f = 0; f < s.frames_per_world; ++f, ++index) {
    const auto& truth = data.truth[pick(rng)].state;
    const float pitch = (10.0f + 6.0f * jitter(rng)) * std::numbers::pi_v<float> / 180.0f;
    const float yaw = 12.0f * jitter(rng) * std::numbers::pi_v<float> / 180.0f;
    Eigen::Isometry3f body_from_optical = Eigen::Isometry3f::Identity();
    body_from_optical.linear() = (Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()) *
                                  Eigen::AngleAxisf(pitch, Eigen::Vector3f::UnitY()))
                                     .toRotationMatrix() *
                                 perception::optical_to_flu();
    body_from_optical.translation() = Eigen::Vector3f(0.3f, 0.0f, 1.5f + 0.3f * jitter(rng));
    Eigen::Isometry3f world_from_body = Eigen::Isometry3f::Identity();
    world_from_body.linear() = truth.rotation.cast<float>();
    world_from_body.translation() = truth.position.cast<float>();
    const auto frame = camera.render(world, world_from_body * body_from_optical,
                                     static_cast<std::uint64_t>(index));
    // The network sees what DnnSegmenter gives it: the image resized bilinearly.
    cv::Mat bgr;
    cv::Mat rgb;
    cv::Mat labels;
    cv::resize(frame.bgr, bgr, cv::Size(s.width, s.height), 0, 0, cv::INTER_LINEAR);
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    cv::resize(frame.labels, labels, cv::Size(s.width, s.height), 0, 0, cv::INTER_NEAREST);
    cv::LUT(labels, cv::Mat(1, 256, CV_8UC1, const_cast<std::uint8_t*>(lut.data())), labels);
    char name[32];
    std::snprintf(name, sizeof name, "%05d", index);
    // cv::imwrite writes PPM from BGR data: hand it the BGR image, the file holds RGB.
    cv::imwrite((folder / ("rgb_" + std::string(name) + ".ppm")).string(), bgr);
    cv::imwrite((folder / ("label_" + std::string(name) + ".pgm")).string(), labels);
  }
  return index;
}

void write_info(const Settings& s, int val_worlds) {
  const auto palette = perception::cityscapes_palette();
  std::ofstream info(s.out / "info.json");
  info << "{\n  \"train_description\": \"" << s.worlds << " street worlds, seeds " << s.first_seed
       << ".." << s.first_seed + s.worlds - 1 << ", " << s.frames_per_world << " frames each\",\n"
       << "  \"val_description\": \"" << val_worlds << " other worlds, seeds "
       << s.first_seed + s.worlds << ".." << s.first_seed + s.worlds + val_worlds - 1 << "\",\n"
       << "  \"map_classes\": " << perception::kSimMapClasses << ",\n  \"colors\": {";
  for (std::size_t m = 0; m < kModelTrainIds.size(); ++m) {
    const auto& entry = palette[kModelTrainIds[m]];
    info << (m ? ", " : "") << "\"" << entry.name << "\": [" << int(entry.color[0]) << ", "
         << int(entry.color[1]) << ", " << int(entry.color[2]) << "]";
  }
  info << "},\n  \"map_class\": {";
  for (std::size_t m = 0; m < kModelTrainIds.size(); ++m) {
    const auto c = perception::sim_map_class(kModelTrainIds[m]);
    info << (m ? ", " : "") << "\"" << palette[kModelTrainIds[m]].name
         << "\": " << (c == perception::kNoLabel ? "\"drop\"" : std::to_string(c));
  }
  info << "},\n  \"names\": \"";
  for (std::size_t m = 0; m < kModelTrainIds.size(); ++m) {
    info << (m ? "," : "") << palette[kModelTrainIds[m]].name;
  }
  info << "\"\n}\n";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"semap-render-dataset: simulated camera frames with true classes, for training"};
  Settings s;
  int val_worlds = 2;
  app.add_option("--out", s.out, "output folder (train/, val/, info.json)")->required();
  app.add_option("--first-seed", s.first_seed, "world seed of the first training world");
  app.add_option("--worlds", s.worlds, "training worlds")->check(CLI::PositiveNumber);
  app.add_option("--val-worlds", val_worlds,
                 "validation worlds (the seeds after the training ones)")
      ->check(CLI::PositiveNumber);
  app.add_option("--frames", s.frames_per_world, "frames per world")->check(CLI::PositiveNumber);
  app.add_option("--width", s.width, "image width (the network's input)")
      ->check(CLI::Range(32, 1280));
  app.add_option("--height", s.height, "image height")->check(CLI::Range(32, 960));
  CLI11_PARSE(app, argc, argv);
  for (const char* split : {"train", "val"}) std::filesystem::create_directories(s.out / split);
  int index = 0;
  for (int w = 0; w < s.worlds; ++w)
    index = render_world(s, s.first_seed + w, s.out / "train", index);
  std::printf("semap-render-dataset: %d training frames\n", index);
  int val_index = 0;
  for (int w = 0; w < val_worlds; ++w) {
    val_index = render_world(s, s.first_seed + s.worlds + w, s.out / "val", val_index);
  }
  std::printf("semap-render-dataset: %d validation frames\n", val_index);
  write_info(s, val_worlds);
  return 0;
}
