// GNSS faults injected into the running robot: onboard::Pipeline on the simulated rig (the real
// GNSS driver on a pty, the estimation, perception and mapping stages; DDS off), one 78 s drive
// with the firmware emulator's scheduled faults (rig.faults):
//   - the receiver silent from 25 s for 30 s: the pose continues on the IMU, its position sigma
//     grows, mapping pauses once the sigma passes map.max_position_sigma_m and resumes when fixes
//     return; the map made before, during and after agrees with the simulated world as well;
//   - every fix 50 m north from 65 s for 5 s (multipath): the fixes are gated and counted, the
//     pose does not jump.
// The drive runs once (SetUpTestSuite); each test checks one behaviour on what it recorded.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <unordered_set>
#include <vector>

#include "semap/dds_idl/map_publisher.hpp"
#include "semap/onboard/onboard_config.hpp"
#include "semap/onboard/pipeline.hpp"
#include "semap/sim/report.hpp"
#include "semap/sim/rig.hpp"
#include "semap/sim/rig_config.hpp"

namespace semap {
namespace {

namespace fs = std::filesystem;

constexpr double kSilenceAt = 25.0;
constexpr double kSilence = 30.0;
constexpr double kJumpAt = 65.0;
constexpr double kJump = 5.0;
constexpr double kJumpM = 50.0;
constexpr double kDuration = 78.0;
constexpr double kMaxSigma = 1.0;  // map.max_position_sigma_m (the default)

std::string slurp(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), {}};
}

void replace(std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("config/sim.yaml lacks: " + from);
  text.replace(at, from.size(), to);
}

// config/sim.yaml with the faults, a cheaper camera (320x240 at 10 Hz, painted in class colours
// and segmented by the palette: the map's errors are then the pose's, not the segmenter's), no
// DDS, no files.
fs::path write_config(const fs::path& dir) {
  std::string yaml = slurp(fs::path(SEMAP_SOURCE_DIR) / "config/sim.yaml");
  char faults[256];
  std::snprintf(faults, sizeof faults,
                "  duration_s: %.0f\n  faults: {gnss_silent_at_s: %.0f, gnss_silent_s: %.0f, "
                "gnss_jump_at_s: %.0f, gnss_jump_s: %.0f, gnss_jump_m: %.0f}",
                kDuration, kSilenceAt, kSilence, kJumpAt, kJump, kJumpM);
  replace(yaml, "  duration_s: 40", faults);
  replace(yaml, "camera_image: rgb ", "camera_image: classes ");
  replace(yaml, "  width: 640\n  height: 480\n  fps: 15", "  width: 320\n  height: 240\n  fps: 10");
  replace(yaml, "  kind: onnx ", "  kind: palette ");
  replace(yaml, "  model_card: models/semap-seg.yaml\n", "");
  replace(yaml, "  save_path: build/sim_map.smap\n", "");
  replace(yaml, "  checkpoint_s: 10 ", "  checkpoint_s: 0 ");
  replace(yaml, "  max_position_sigma_m: 1.0 ",
          "  max_position_sigma_m: " + std::to_string(kMaxSigma) + " ");
  replace(yaml, "dds:\n", "dds:\n  enabled: false\n");
  fs::create_directories(dir);
  const fs::path path = dir / "gnss-faults.yaml";
  std::ofstream(path) << yaml;
  return path;
}

// What the test loop saw at one tick: the filter against the truth and the stages' counters.
struct Tick {
  double t = 0.0;  // drive time (from its first sample) of the filter's latest pose
  Eigen::Vector3d error = Eigen::Vector3d::Zero();
  double sigma = 0.0;  // the pose's position sigma as the pose history gets it
  std::uint64_t gnss_rejected = 0;
  std::uint64_t gnss_applied = 0;
  std::uint64_t clouds = 0;
  std::uint64_t uncertain = 0;
};

struct CellKey {
  common::BlockIndex block;
  std::size_t cell;
  bool operator==(const CellKey&) const = default;
};
struct CellKeyHash {
  std::size_t operator()(const CellKey& k) const {
    return common::BlockIndexHash()(k.block) ^ (k.cell * 2654435761u);
  }
};
using CellSet = std::unordered_set<CellKey, CellKeyHash>;

// The occupied cells of the map at one moment, and how many of those first occupied since the
// previous snapshot carry the world's true class at their centre.
struct Phase {
  std::string name;
  std::size_t new_cells = 0;
  std::size_t new_cells_right = 0;
  double agreement() const {
    return new_cells ? static_cast<double>(new_cells_right) / static_cast<double>(new_cells) : 0.0;
  }
};

struct DriveRecord {
  std::vector<Tick> ticks;
  std::vector<Phase> phases;
  onboard::EstimationStageStats estimation;
  onboard::PerceptionStageStats perception;
  sim::InjectedFaults injected;
  std::vector<std::string> summary;
};

// The map's occupied cells now; those not in `seen` are scored against the world and added.
Phase snapshot(const std::string& name, const onboard::MappingStage& mapping,
               const sim::SimRig& rig, const Eigen::Vector3f& map_to_sim, CellSet& seen) {
  Phase phase{name};
  const auto& blocks = mapping.blocks();
  std::vector<common::BlockIndex> indices;
  blocks.for_each_block([&](const common::BlockIndex& b) { indices.push_back(b); });
  dds_idl::BlockSnapshot block;
  for (const auto& index : indices) {
    if (!blocks.read_cells(index, block)) continue;
    const auto tolerance = block.resolution * std::sqrt(3.0f) / 2.0f;
    for (std::size_t c = 0; c < block.cell_count(); ++c) {
      if (block.state[c] != common::CellState::kOccupied) continue;
      if (!seen.insert({index, c}).second) continue;
      ++phase.new_cells;
      const auto truth = rig.world().class_at(block.cell_center(c) + map_to_sim, tolerance);
      if (truth == block.argmax_class[c]) ++phase.new_cells_right;
    }
  }
  return phase;
}

DriveRecord drive() {
  const fs::path dir =
      fs::temp_directory_path() / ("semap-gnss-faults-" + std::to_string(getpid()));
  sim::SimRigConfig sim_config;
  const auto config =
      onboard::load_onboard_config(write_config(dir), sim::sim_rig_keys(sim_config));
  sim::SimRig* rig = nullptr;
  onboard::Pipeline pipeline(config, [&](const onboard::SensorRings& rings) {
    auto r = std::make_unique<sim::SimRig>(config, sim_config, rings);
    rig = r.get();
    return r;
  });
  DriveRecord run;
  CellSet seen;
  std::optional<Eigen::Vector3f> map_to_sim;
  // Map snapshots at the phase boundaries (simulated time; a second after the silence ends so
  // the clouds posed before the first fix came back count to it).
  const std::vector<std::pair<double, std::string>> boundaries = {
      {kSilenceAt, "before"}, {kSilenceAt + kSilence + 1.0, "silence"}, {kJumpAt, "after"}};
  std::size_t next_boundary = 0;
  pipeline.start();
  while (!pipeline.finished()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
    pipeline.tick();
    const auto est = pipeline.estimation();
    const auto pose = sim::pose_vs_truth(*rig, est);
    if (!pose) continue;
    if (!map_to_sim) map_to_sim = sim::sim_from_map(*rig, *est.anchor).cast<float>();
    const auto perception = pipeline.perception().value_or(onboard::PerceptionStageStats{});
    Tick tick;
    // The emulator's windows count from the drive's first sample (simulated stamps start at 1 s).
    tick.t = common::seconds_between(pose->stamp, rig->started_at()) -
             rig->data().imu.front().stamp.seconds();
    tick.error = pose->estimate - pose->truth;
    tick.sigma = est.latest->position_sigma_m;
    tick.gnss_rejected = est.estimator.gnss_rejected;
    tick.gnss_applied = est.estimator.gnss_applied;
    tick.clouds = perception.clouds;
    tick.uncertain = perception.uncertain_pose;
    run.ticks.push_back(tick);
    if (next_boundary < boundaries.size() && tick.t >= boundaries[next_boundary].first) {
      run.phases.push_back(snapshot(boundaries[next_boundary].second, pipeline.mapping_stage(),
                                    *rig, *map_to_sim, seen));
      ++next_boundary;
    }
  }
  pipeline.stop();
  if (map_to_sim) {
    run.phases.push_back(snapshot("jump", pipeline.mapping_stage(), *rig, *map_to_sim, seen));
  }
  run.estimation = pipeline.estimation();
  run.perception = pipeline.perception().value_or(onboard::PerceptionStageStats{});
  run.injected = rig->emulator_stats().injected;
  run.summary = pipeline.summary();
  for (const auto& line : run.summary) std::printf("%s\n", line.c_str());
  for (const auto& p : run.phases) {
    std::printf("map cells first occupied %-8s: %zu, %.3f with the true class\n", p.name.c_str(),
                p.new_cells, p.agreement());
  }
  fs::remove_all(dir);
  return run;
}

class GnssFaults : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { run_ = std::make_unique<DriveRecord>(drive()); }
  static void TearDownTestSuite() { run_.reset(); }

  // The ticks whose pose lies in [t0, t1) of simulated time.
  static std::vector<Tick> between(double t0, double t1) {
    std::vector<Tick> out;
    for (const auto& t : run_->ticks) {
      if (t.t >= t0 && t.t < t1) out.push_back(t);
    }
    return out;
  }
  static double max_error(const std::vector<Tick>& ticks) {
    double worst = 0.0;
    for (const auto& t : ticks) worst = std::max(worst, t.error.norm());
    return worst;
  }
  static const Tick& at(double t) {
    const auto it = std::find_if(run_->ticks.begin(), run_->ticks.end(),
                                 [t](const Tick& k) { return k.t >= t; });
    if (it == run_->ticks.end()) return run_->ticks.back();
    return *it;
  }

  static std::unique_ptr<DriveRecord> run_;
};
std::unique_ptr<DriveRecord> GnssFaults::run_;

TEST_F(GnssFaults, TheDriveRanWithBothFaults) {
  ASSERT_TRUE(run_->estimation.initialised);
  EXPECT_EQ(run_->injected.gnss_silent_epochs, 300u);  // 30 s at 10 Hz
  EXPECT_EQ(run_->injected.gnss_jumps, 50u);           // 5 s at 10 Hz
  ASSERT_FALSE(between(10.0, kSilenceAt).empty());
  ASSERT_FALSE(between(kJumpAt + kJump + 2.0, kDuration).empty());
  ASSERT_EQ(run_->phases.size(), 4u);
}

// Thirty seconds without fixes: the IMU carries the pose, and the filter says it is less sure.
TEST_F(GnssFaults, SilenceThePoseContinuesOnTheImuAndItsSigmaGrows) {
  const auto before = between(kSilenceAt - 5.0, kSilenceAt);
  const auto silent = between(kSilenceAt + 0.5, kSilenceAt + kSilence);
  ASSERT_FALSE(before.empty());
  ASSERT_FALSE(silent.empty());
  // No fix is applied while the receiver is silent; the pose still moves with the vehicle.
  EXPECT_EQ(silent.back().gnss_applied, silent.front().gnss_applied);
  const double sigma_before = std::max_element(before.begin(), before.end(), [](auto& a, auto& b) {
                                return a.sigma < b.sigma;
                              })->sigma;
  const double sigma_end = silent.back().sigma;
  const double error_silent = max_error(silent);
  std::printf(
      "silence: sigma before %.3f m, at its end %.3f m; position error max %.3f m "
      "before, %.3f m during\n",
      sigma_before, sigma_end, max_error(before), error_silent);
  EXPECT_LT(sigma_before, 0.5);
  EXPECT_GT(sigma_end, 3.0 * kMaxSigma);
  // It grows through the silence: each second's sigma above the one before.
  for (double t = kSilenceAt + 2.0; t + 1.0 < kSilenceAt + kSilence; t += 1.0) {
    EXPECT_GT(at(t + 1.0).sigma, at(t).sigma) << "at " << t << " s";
  }
  // Dead reckoning for 30 s (150 m driven): metres (8 to 11 m in four runs: where the filter
  // stands when the fixes stop depends on when the driver read them), and within 3 sigma of what
  // the filter claims.
  EXPECT_LT(error_silent, 20.0);
  for (const auto& t : silent) EXPECT_LT(t.error.norm(), 3.0 * t.sigma + 0.5) << "at " << t.t;
  // Fixes return: the pose is pulled back and the sigma falls below the limit within seconds.
  const auto after = between(kSilenceAt + kSilence + 3.0, kJumpAt);
  ASSERT_FALSE(after.empty());
  std::printf("after the silence: position error max %.3f m from 3 s on\n", max_error(after));
  EXPECT_LT(max_error(after), 1.5);
  for (const auto& t : after) EXPECT_LT(t.sigma, kMaxSigma) << "at " << t.t;
}

// Mapping stops while the sigma is above map.max_position_sigma_m, and starts again after.
TEST_F(GnssFaults, SilenceMappingPausesAboveTheSigmaLimitAndResumes) {
  const Tick& start = at(kSilenceAt);
  const Tick& end = at(kSilenceAt + kSilence + 2.0);
  const Tick& last = run_->ticks.back();
  std::printf(
      "clouds: %llu mapped before the silence, %llu during, %llu after; %llu dropped "
      "as too uncertain\n",
      static_cast<unsigned long long>(start.clouds),
      static_cast<unsigned long long>(end.clouds - start.clouds),
      static_cast<unsigned long long>(last.clouds - end.clouds),
      static_cast<unsigned long long>(run_->perception.uncertain_pose));
  EXPECT_EQ(start.uncertain, 0u) << "nothing dropped before the silence";
  // 10 Hz camera: most of the 30 s is paused.
  EXPECT_GT(end.uncertain, 150u);
  EXPECT_EQ(run_->perception.uncertain_pose, end.uncertain) << "nothing dropped after it";
  // While the sigma is above the limit (with a margin for the clouds in flight), no cloud.
  for (std::size_t i = 1; i < run_->ticks.size(); ++i) {
    const Tick& a = run_->ticks[i - 1];
    const Tick& b = run_->ticks[i];
    if (a.sigma > 1.2 * kMaxSigma && b.sigma > 1.2 * kMaxSigma) {
      EXPECT_EQ(b.clouds, a.clouds) << "a cloud mapped at " << b.t << " s, sigma " << b.sigma;
    }
  }
  // Mapping resumed: the clouds after the silence go into the map again.
  EXPECT_GT(last.clouds - end.clouds, 100u);
}

// Nothing posed badly went into the map: while clouds were mapped the pose was right, and the
// cells first occupied during and after the silence agree with the world as well as those before.
TEST_F(GnssFaults, SilenceLeavesNoSmearInTheMap) {
  double worst = 0.0;
  double worst_t = 0.0;
  for (std::size_t i = 1; i < run_->ticks.size(); ++i) {
    const Tick& a = run_->ticks[i - 1];
    const Tick& b = run_->ticks[i];
    if (b.clouds == a.clouds) continue;
    const double e = std::max(a.error.norm(), b.error.norm());
    if (e > worst) {
      worst = e;
      worst_t = b.t;
    }
  }
  std::printf("largest position error while clouds were mapped: %.3f m at %.1f s\n", worst,
              worst_t);
  // The largest is at the first fix after the silence (about 1 m; 8.6 m with no limit).
  EXPECT_LT(worst, 2.0);
  const auto& phases = run_->phases;
  ASSERT_EQ(phases.size(), 4u);
  const Phase& before = phases[0];
  ASSERT_GT(before.new_cells, 10'000u);
  EXPECT_GT(before.agreement(), 0.5);
  EXPECT_GT(phases[1].agreement(), before.agreement() - 0.1) << "cells mapped in the silence";
  EXPECT_GT(phases[2].agreement(), before.agreement() - 0.1) << "cells mapped after it";
  EXPECT_GT(phases[2].new_cells, 5'000u) << "mapping resumed";
}

// A 50 m multipath jump for 5 s: the fixes are gated and counted, and the pose stays on the
// truth, with no step between two ticks. After ten gated fixes the estimator takes the jump for
// a receiver frame change and re-anchors (the remaining jumped fixes agree with the pose in the
// shifted frame); when the receiver comes back, ten more are gated and it returns to the frame
// it left. Measured: 20 gated, the error at most 0.63 m (1.43 m, and ~1 m for good, when it
// added a second noisy shift instead of returning).
// A loaded machine delays the driver's reads (a fix is stamped when read), and the odd fix is
// gated outside the faults too: the count starts just before the jump.
TEST_F(GnssFaults, JumpIsGatedCountedAndThePoseDoesNotJump) {
  const Tick& before = at(kJumpAt - 0.5);
  const Tick& after = run_->ticks.back();
  const auto window = between(kJumpAt - 2.0, kDuration);
  const std::uint64_t rejected = after.gnss_rejected - before.gnss_rejected;
  double step = 0.0;
  for (std::size_t i = 1; i < window.size(); ++i) {
    step = std::max(step, (window[i].error - window[i - 1].error).norm());
  }
  std::printf(
      "jump: %llu fixes gated out, %llu re-anchorings; position error max %.3f m, "
      "largest change of the error between ticks %.3f m\n",
      static_cast<unsigned long long>(rejected),
      static_cast<unsigned long long>(run_->estimation.estimator.reanchors), max_error(window),
      step);
  EXPECT_GE(rejected, 20u);
  EXPECT_LE(rejected, run_->injected.gnss_jumps + 10u);
  EXPECT_EQ(run_->estimation.estimator.reanchors_back, 1u) << "back in the frame it left";
  EXPECT_LT(max_error(window), 1.0);
  EXPECT_LT(step, 0.3);
  EXPECT_EQ(run_->perception.uncertain_pose, at(kJumpAt).uncertain);
}

}  // namespace
}  // namespace semap
