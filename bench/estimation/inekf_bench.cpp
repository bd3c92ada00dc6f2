// Cost per call of the filter steps (targets: InEKF propagate <= 0.3 us with per-axis noise,
// GNSS correction <= 2 us), with the quaternion ESKF baseline for comparison. The public
// contact-aided InEKF (dynamic-size Eigen) takes about 3.6-4.5 us per propagate on the
// reference machine.
// The InEKF defers its covariance between reads; a propagate-only loop pays the flushes of
// its bounded windows, and `inekf/mix_per_imu_sample` runs a realistic mix (100 Hz IMU, a GNSS
// correction at 10 Hz, the pose covariance read at 50 Hz for odometry) per IMU sample.
// `inekf/propagate_per_axis` is the same loop with different noise on every axis, and
// `inekf/propagate_plain` the textbook per-step propagation (one-step mode) with that noise.
#include <benchmark/benchmark.h>

#include <array>
#include <random>

#include "semap/estimation/chi_square.hpp"
#include "semap/estimation/left_inekf.hpp"
#include "semap/estimation/quaternion_eskf.hpp"
#include "semap/estimation/so3.hpp"

namespace {

using semap::estimation::FilterParams;
using semap::estimation::Matrix15;
using semap::estimation::NavState;

constexpr std::size_t kInputs = 256;

struct Inputs {
  std::array<Eigen::Vector3d, kInputs> gyro;
  std::array<Eigen::Vector3d, kInputs> accel;
  std::array<Eigen::Vector3d, kInputs> noise;
  Inputs() {
    std::mt19937_64 rng(1);
    std::normal_distribution<double> n(0.0, 1.0);
    for (std::size_t i = 0; i < kInputs; ++i) {
      gyro[i] = Eigen::Vector3d(0.05 * n(rng), 0.05 * n(rng), 0.2 + 0.05 * n(rng));
      accel[i] = Eigen::Vector3d(0.5 * n(rng), 0.5 * n(rng), 9.81 + 0.1 * n(rng));
      noise[i] = Eigen::Vector3d(n(rng), n(rng), n(rng));
    }
  }
};

// The GNSS fix model both correction benchmarks use: 1 m noise, antenna lever arm, 99.9 % gate.
struct GnssSetup {
  double gate2 = semap::estimation::chi_square_quantile(0.999, 3);
  Eigen::Matrix3d noise = Eigen::Matrix3d::Identity();
  Eigen::Vector3d lever{0.2, 0.0, 1.2};
};

NavState start_state() {
  NavState s;
  s.rotation = semap::estimation::rotation_from_rpy(0.01, -0.02, 0.7);
  s.velocity = Eigen::Vector3d(8.0, 1.0, 0.0);
  return s;
}

Matrix15 start_covariance() {
  Matrix15 p = Matrix15::Identity() * 0.01;
  p.block<3, 3>(6, 6) *= 100.0;
  return p;
}

// A datasheet-style IMU whose axes differ (here the z axis is the noisier one).
FilterParams per_axis_params() {
  FilterParams params;
  params.noise.gyro_noise = Eigen::Vector3d(1.4e-4, 1.4e-4, 2.1e-4);
  params.noise.accel_noise = Eigen::Vector3d(1.6e-3, 1.6e-3, 2.4e-3);
  params.noise.gyro_bias_walk = Eigen::Vector3d(2.0e-5, 2.0e-5, 3.0e-5);
  params.noise.accel_bias_walk = Eigen::Vector3d(3.0e-4, 3.0e-4, 4.5e-4);
  return params;
}

// Drives of 100 s: the inputs' small net acceleration makes an endless drive ever faster
// (kilometres per second after a few million steps), until moving the filter's origin, which
// follows the robot every 100 m, happens every few steps and is what the loop measures.
constexpr std::size_t kStepsPerDrive = 10000;

// One IMU step per iteration, cycling through the recorded inputs; a new drive (untimed)
// every kStepsPerDrive steps.
template <typename Filter>
void run_propagate(benchmark::State& state, Filter& f) {
  const Inputs in;
  f.reset(start_state(), start_covariance());
  std::size_t i = 0;
  std::size_t steps = 0;
  for (auto _ : state) {
    f.propagate(in.gyro[i], in.accel[i], 0.01);
    i = (i + 1) % kInputs;
    benchmark::DoNotOptimize(f);
    if (++steps == kStepsPerDrive) {
      state.PauseTiming();
      f.reset(start_state(), start_covariance());
      steps = 0;
      state.ResumeTiming();
    }
  }
}

template <typename Filter>
void propagate(benchmark::State& state) {
  Filter f{FilterParams{}};
  run_propagate(state, f);
}

// LeftInekf with per-axis noise and `window` steps per covariance window (1: plain per-step).
template <int window>
void inekf_propagate_per_axis(benchmark::State& state) {
  semap::estimation::LeftInekf f(per_axis_params(), window);
  run_propagate(state, f);
}

template <typename Filter>
void gnss_correction(benchmark::State& state) {
  const Inputs in;
  Filter f{FilterParams{}};
  f.reset(start_state(), start_covariance());
  const GnssSetup gnss;
  const NavState s = f.state();
  const Eigen::Vector3d antenna = s.position + s.rotation * gnss.lever;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        f.correct_position(antenna + in.noise[i], gnss.noise, gnss.lever, gnss.gate2));
    i = (i + 1) % kInputs;
  }
}

template <typename Filter>
void mix_per_imu_sample(benchmark::State& state) {
  const Inputs in;
  Filter f{FilterParams{}};
  f.reset(start_state(), start_covariance());
  const GnssSetup gnss;
  std::size_t i = 0;
  for (auto _ : state) {
    f.propagate(in.gyro[i], in.accel[i], 0.01);
    if (i % 2 == 1) {  // odometry at 50 Hz
      benchmark::DoNotOptimize(f.position_covariance_world());
      benchmark::DoNotOptimize(f.rotation_covariance_world());
    }
    if (i % 10 == 9) {  // GNSS at 10 Hz, around the current estimate
      const NavState s = f.state();
      benchmark::DoNotOptimize(
          f.correct_position(s.position + s.rotation * gnss.lever + 0.3 * in.noise[i], gnss.noise,
                             gnss.lever, gnss.gate2));
    }
    i = (i + 1) % kInputs;
    benchmark::DoNotOptimize(f);
  }
}

void transition_only(benchmark::State& state) {
  const Inputs in;
  const FilterParams params;
  const NavState s = start_state();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(semap::estimation::InekfImuStep::compute(
        s.rotation, s.velocity, s.position, in.gyro[i], in.accel[i], 0.01, params.gravity));
    i = (i + 1) % kInputs;
  }
}

BENCHMARK(propagate<semap::estimation::LeftInekf>)->Name("inekf/propagate");
BENCHMARK(inekf_propagate_per_axis<semap::estimation::LeftInekf::kDefaultWindowSteps>)
    ->Name("inekf/propagate_per_axis");
BENCHMARK(inekf_propagate_per_axis<1>)->Name("inekf/propagate_plain");
BENCHMARK(gnss_correction<semap::estimation::LeftInekf>)->Name("inekf/gnss_correction");
BENCHMARK(mix_per_imu_sample<semap::estimation::LeftInekf>)->Name("inekf/mix_per_imu_sample");
BENCHMARK(transition_only)->Name("inekf/imu_step_only");
BENCHMARK(propagate<semap::estimation::QuaternionEskf>)->Name("eskf/propagate");
BENCHMARK(gnss_correction<semap::estimation::QuaternionEskf>)->Name("eskf/gnss_correction");
BENCHMARK(mix_per_imu_sample<semap::estimation::QuaternionEskf>)->Name("eskf/mix_per_imu_sample");

}  // namespace

BENCHMARK_MAIN();
