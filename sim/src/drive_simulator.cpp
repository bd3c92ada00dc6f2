#include "semap/sim/drive_simulator.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "semap/estimation/so3.hpp"

namespace semap::sim {

using estimation::DriveData;
using estimation::Geodetic;
using estimation::LocalEnu;
using estimation::NavState;
using estimation::rotation_from_rpy;
using estimation::TruthSample;

namespace {

using Eigen::Vector3d;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr int kSubsteps = 10;  // RK4 steps per IMU interval (even: midpoints lie on the grid)
constexpr double kDiffStep = 1e-5;

// Smooth 0 -> 1 over `length` seconds.
double ramp(double t, double length) {
  if (t <= 0.0) return 0.0;
  if (t >= length) return 1.0;
  const double x = t / length;
  return x * x * (3.0 - 2.0 * x);
}

// Speed, yaw rate and climb rate as functions of time: the whole trajectory.
class Profile {
 public:
  explicit Profile(const SimulatorConfig& c) : c_(c) {}

  double speed(double t) const {
    const double tm = t - c_.static_s;
    const double r = ramp(tm, kRampS);
    if (c_.scenario != Scenario::kCar) return c_.speed_m_s * r;
    return c_.speed_m_s * r * (1.0 + 0.3 * std::sin(kTwoPi * tm / 45.0));
  }
  double yaw_rate(double t) const {
    const double tm = t - c_.static_s;
    const double r = ramp(tm, kRampS);
    if (c_.scenario == Scenario::kLoops) return speed(t) * loop_curvature(distance(t));
    if (c_.scenario == Scenario::kFigureEight) {
      // Alternating loops of radius ~ speed / omega.
      const double omega = c_.speed_m_s / 25.0;
      const double period = 2.0 * kTwoPi / omega;
      return r * omega * std::tanh(3.0 * std::sin(kTwoPi * tm / period));
    }
    return r * (0.12 * std::sin(kTwoPi * tm / 30.0) + 0.08 * std::sin(kTwoPi * tm / 11.0 + 1.0));
  }
  double climb(double t) const {
    const double tm = t - c_.static_s;
    if (c_.scenario != Scenario::kCar) return 0.0;
    return ramp(tm, kRampS) * 0.3 * std::sin(kTwoPi * tm / 25.0);
  }
  double pitch(double t) const {
    const double s = speed(t);
    return s > 1e-9 ? -std::atan2(climb(t), s) : 0.0;
  }

 private:
  static constexpr double kRampS = 8.0;  // from rest to full speed

  // Distance driven by time t: the integral of speed(), in closed form (ramp is a smoothstep).
  double distance(double t) const {
    const double tm = t - c_.static_s;
    if (tm <= 0.0) return 0.0;
    if (tm >= kRampS) return c_.speed_m_s * (tm - kRampS / 2.0);
    const double x = tm / kRampS;
    return c_.speed_m_s * kRampS * (x * x * x - x * x * x * x / 2.0);
  }

  // kLoops: curvature +1/R on even laps, -1/R on odd ones; each switch is blended over about a
  // metre by tanh, which is odd about the switch, so every lap still turns exactly 2 pi and
  // the drive repeats every two laps.
  double loop_curvature(double s) const {
    constexpr double kBlendM = 0.5;
    const double radius = c_.loop_radius_m;
    const double lap = kTwoPi * radius;
    const double k = std::floor(s / lap);
    const double sign = std::fmod(k, 2.0) == 0.0 ? 1.0 : -1.0;
    double to_switch = (k + 1.0) * lap - s;
    if (k > 0.0) to_switch = std::min(to_switch, s - k * lap);
    return sign * std::tanh(to_switch / kBlendM) / radius;
  }

  SimulatorConfig c_;
};

double derivative(const Profile& p, double (Profile::*f)(double) const, double t) {
  return ((p.*f)(t + kDiffStep) - (p.*f)(t - kDiffStep)) / (2.0 * kDiffStep);
}

// Kinematic state along the profile: yaw and position are integrated, the rest is closed form.
struct Kinematics {
  double yaw = 0.0;
  Vector3d position = Vector3d::Zero();
};

Vector3d velocity_at(const Profile& p, double t, double yaw) {
  const double s = p.speed(t);
  return {s * std::cos(yaw), s * std::sin(yaw), p.climb(t)};
}

Kinematics rk4(const Profile& p, const Kinematics& k, double t, double h) {
  auto f = [&](double tt, const Kinematics& kk) {
    Kinematics d;
    d.yaw = p.yaw_rate(tt);
    d.position = velocity_at(p, tt, kk.yaw);
    return d;
  };
  auto add = [](const Kinematics& a, const Kinematics& d, double s) {
    return Kinematics{a.yaw + s * d.yaw, a.position + s * d.position};
  };
  const Kinematics k1 = f(t, k);
  const Kinematics k2 = f(t + h / 2, add(k, k1, h / 2));
  const Kinematics k3 = f(t + h / 2, add(k, k2, h / 2));
  const Kinematics k4 = f(t + h, add(k, k3, h));
  Kinematics out = k;
  out.yaw += h / 6 * (k1.yaw + 2 * k2.yaw + 2 * k3.yaw + k4.yaw);
  out.position += h / 6 * (k1.position + 2 * k2.position + 2 * k3.position + k4.position);
  return out;
}

struct Motion {
  NavState state;                    // without biases
  Vector3d gyro = Vector3d::Zero();  // true body rate
  Vector3d specific_force = Vector3d::Zero();
};

Motion motion_at(const Profile& p, const Kinematics& k, double t, const Vector3d& gravity) {
  Motion m;
  const double pitch = p.pitch(t);
  m.state.rotation = rotation_from_rpy(0.0, pitch, k.yaw);
  m.state.velocity = velocity_at(p, t, k.yaw);
  m.state.position = k.position;
  const double s = p.speed(t);
  const double s_dot = derivative(p, &Profile::speed, t);
  const double yaw_rate = p.yaw_rate(t);
  const Vector3d accel(s_dot * std::cos(k.yaw) - s * yaw_rate * std::sin(k.yaw),
                       s_dot * std::sin(k.yaw) + s * yaw_rate * std::cos(k.yaw),
                       derivative(p, &Profile::climb, t));
  // R = Rz(yaw) Ry(pitch): body rate = Ry^T e_z yaw_rate + e_y pitch_rate.
  const double pitch_rate = derivative(p, &Profile::pitch, t);
  m.gyro = Vector3d(-std::sin(pitch) * yaw_rate, pitch_rate, std::cos(pitch) * yaw_rate);
  m.specific_force = m.state.rotation.transpose() * (accel - gravity);
  return m;
}

// True heading of the body x axis (clockwise from north) plus `unit_noise` sigmas, [0, 360).
double heading_deg(const Eigen::Matrix3d& rotation, const SimulatorConfig& c, double unit_noise) {
  const Vector3d forward = rotation.col(0);
  const double h = std::atan2(forward.x(), forward.y()) * 180.0 / std::numbers::pi +
                   c.gnss_heading_sigma_deg * unit_noise;
  const double wrapped = std::fmod(h, 360.0);
  return wrapped < 0.0 ? wrapped + 360.0 : wrapped;
}

}  // namespace

DriveData simulate(const SimulatorConfig& c) {
  if (!(c.imu_rate_hz > 0.0) || !(c.gnss_rate_hz > 0.0) || !(c.duration_s > 0.0) ||
      !(c.loop_radius_m > 0.0)) {
    throw std::invalid_argument("simulate: rates, duration and loop radius must be positive");
  }
  DriveData out;
  out.origin = c.origin;
  out.lever_arm = c.lever_arm;
  const LocalEnu enu(c.origin);
  const Profile profile(c);
  std::mt19937_64 rng(c.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto gaussian3 = [&] { return Vector3d(normal(rng), normal(rng), normal(rng)); };
  std::uniform_real_distribution<double> uniform(0.0, 1.0);

  const double dt = 1.0 / c.imu_rate_hz;
  const double h = dt / kSubsteps;
  const auto steps = static_cast<std::size_t>(std::floor(c.duration_s * c.imu_rate_hz));
  const double t0 = 1.0;  // stamps start at 1 s, keeping 0 free as "unset"
  const auto& n = c.imu_noise;
  const Vector3d gyro_sd = n.gyro_noise * std::sqrt(c.imu_rate_hz);
  const Vector3d accel_sd = n.accel_noise * std::sqrt(c.imu_rate_hz);
  Vector3d bg = c.initial_gyro_bias_sigma * gaussian3();
  Vector3d ba = c.initial_accel_bias_sigma * gaussian3();

  out.truth.reserve(steps + 1);
  out.imu.reserve(steps + 1);
  Kinematics k;
  k.yaw = c.initial_yaw_rad;
  double t = 0.0;
  double next_gnss = c.gnss_phase_s;
  double dropout_until = -1.0;
  double next_dropout_check = 0.0;

  for (std::size_t i = 0; i <= steps; ++i) {
    Motion mid;
    if (i > 0) {
      for (int j = 0; j < kSubsteps; ++j) {
        // GNSS fixes are taken on the fine grid as it passes their time.
        if (next_gnss < t + h) {
          const double tg = next_gnss;
          const Kinematics kg = rk4(profile, k, t, tg - t);
          const Motion mg = motion_at(profile, kg, tg, c.gravity);
          next_gnss += 1.0 / c.gnss_rate_hz;
          while (next_dropout_check <= tg) {
            if (uniform(rng) < c.dropouts_per_minute / 60.0)
              dropout_until = tg + c.dropout_duration_s;
            next_dropout_check += 1.0;
          }
          if (tg >= dropout_until) {
            Vector3d antenna = mg.state.position + mg.state.rotation * c.lever_arm;
            antenna += c.gnss_sigma_m * gaussian3();
            for (const auto& jump : c.jumps) {
              if (tg >= jump.start_s && tg < jump.start_s + jump.duration_s) antenna += jump.offset;
            }
            const Geodetic g = enu.to_geodetic(antenna);
            common::GnssFix fix;
            fix.stamp = common::Stamp::from_seconds(t0 + tg);
            fix.latitude_deg = g.latitude_deg;
            fix.longitude_deg = g.longitude_deg;
            fix.altitude_m = g.altitude_m;
            fix.covariance = Eigen::Matrix3d::Identity() * c.gnss_sigma_m * c.gnss_sigma_m;
            fix.quality = common::FixQuality::kGps;
            fix.mode = common::FixMode::k3D;
            fix.satellites = 12;
            if (c.gnss_velocity) {
              fix.velocity_enu = mg.state.velocity + c.gnss_velocity_sigma_m_s * gaussian3();
            }
            if (c.gnss_heading) fix.heading_deg = heading_deg(mg.state.rotation, c, normal(rng));
            out.gnss.push_back(fix);
          }
        }
        k = rk4(profile, k, t, h);
        t += h;
        if (j == kSubsteps / 2 - 1) mid = motion_at(profile, k, t, c.gravity);
      }
      // Biases walk over the interval; the sample carries the end-of-interval bias.
      bg += (std::sqrt(dt) * n.gyro_bias_walk).cwiseProduct(gaussian3());
      ba += (std::sqrt(dt) * n.accel_bias_walk).cwiseProduct(gaussian3());
    } else {
      mid = motion_at(profile, k, t, c.gravity);
    }
    const Motion now = motion_at(profile, k, t, c.gravity);
    TruthSample truth;
    truth.stamp = common::Stamp::from_seconds(t0 + static_cast<double>(i) * dt);
    truth.state = now.state;
    truth.state.gyro_bias = bg;
    truth.state.accel_bias = ba;
    out.truth.push_back(truth);

    common::ImuSample imu;
    imu.stamp = truth.stamp;
    imu.sequence = static_cast<std::uint32_t>(i);
    imu.gyro = mid.gyro + bg + gyro_sd.cwiseProduct(gaussian3());
    imu.accel = mid.specific_force + ba + accel_sd.cwiseProduct(gaussian3());
    out.imu.push_back(imu);
  }
  return out;
}

}  // namespace semap::sim
