// OXTS packets written from the simulator read back as the simulator's truth and IMU: the
// frames and signs of oxts_to_inputs checked against a known motion.
#include "semap/estimation/oxts_writer.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "semap/estimation/oxts_reader.hpp"
#include "semap/estimation/so3.hpp"
#include "semap/sim/drive_simulator.hpp"

namespace semap::estimation {
namespace {

TEST(OxtsWriter, TimestampRoundTrips) {
  const common::Stamp stamp(1317042145LL * 1'000'000'000LL + 964389445LL);
  const std::string text = format_kitti_timestamp(stamp);
  EXPECT_EQ(text, "2011-09-26 13:02:25.964389445");
  ASSERT_TRUE(parse_kitti_timestamp(text).has_value());
  EXPECT_EQ(parse_kitti_timestamp(text)->ns, stamp.ns);
}

DriveData simulated_car(double seconds) {
  sim::SimulatorConfig sc;
  sc.duration_s = seconds;
  return sim::simulate(sc);
}

// The simulator's car through writer, parser and conversion: every IMU sample, truth pose and
// (noise-free) fix equals the simulator's, so the reader's frames (body x forward, y left,
// z up; ENU world; yaw from east) and signs are the simulator's.
TEST(OxtsWriter, ConversionMatchesTheSimulatorsTruth) {
  const DriveData sim = simulated_car(40.0);
  const LocalEnu enu(sim.origin);
  OxtsData data;
  for (std::size_t i = 0; i < sim.imu.size(); i += 7) {
    const OxtsRecord written = oxts_record_from_state(sim.truth[i].state, sim.imu[i], enu, 0.3);
    std::string error;
    auto read = parse_oxts_line(format_oxts_line(written), error);
    ASSERT_TRUE(read.has_value()) << error;
    read->stamp = written.stamp;
    data.records.push_back(*read);
  }
  const DriveData in = oxts_to_inputs(data, 1e-9, 1);
  ASSERT_EQ(in.imu.size(), data.records.size());
  const LocalEnu back(in.origin);
  for (std::size_t k = 0; k < in.imu.size(); ++k) {
    const std::size_t i = 7 * k;
    const NavState& truth = sim.truth[i].state;
    // Positions relative to the first packet (the conversion anchors there).
    const Eigen::Vector3d expected = truth.position - sim.truth[0].state.position;
    EXPECT_LT((in.truth[k].state.position - expected).norm(), 1e-3) << k;
    EXPECT_LT((in.truth[k].state.rotation - truth.rotation).norm(), 1e-7) << k;
    EXPECT_LT((in.truth[k].state.velocity - truth.velocity).norm(), 1e-6) << k;
    EXPECT_LT((in.imu[k].accel - sim.imu[i].accel).norm(), 1e-6) << k;
    EXPECT_LT((in.imu[k].gyro - sim.imu[i].gyro).norm(), 1e-6) << k;
    const auto& f = in.gnss[k];
    EXPECT_LT((back.to_enu({f.latitude_deg, f.longitude_deg, f.altitude_m}) - expected).norm(),
              1e-3)
        << k;
  }
  // Signs a user can check on a real drive: at rest the specific force points up (+z, about
  // g); the car's speed is along its body x.
  EXPECT_NEAR(in.imu.front().accel.z(), 9.80665, 0.1);
  for (std::size_t k = 0; k < in.truth.size(); ++k) {
    const NavState& s = in.truth[k].state;
    const Eigen::Vector3d v_body = s.rotation.transpose() * s.velocity;
    if (s.velocity.norm() > 5.0) {
      EXPECT_GT(v_body.x(), 0.99 * s.velocity.norm()) << k;
    }
  }
}

TEST(OxtsWriter, PacketAccuracyIsTheFixSigma) {
  const DriveData sim = simulated_car(10.0);
  OxtsData data;
  for (std::size_t i = 0; i < 3; ++i) {
    data.records.push_back(oxts_record_from_state(
        sim.truth[i].state, sim.imu[i], LocalEnu(sim.origin), 0.5 * static_cast<double>(i)));
  }
  const DriveData in = oxts_to_inputs(data, 7.0, 1, OxtsGnssNoise::kPacketAccuracy);
  EXPECT_DOUBLE_EQ(in.gnss[0].covariance(0, 0), kMinPacketSigmaM * kMinPacketSigmaM);
  EXPECT_DOUBLE_EQ(in.gnss[1].covariance(1, 1), 0.25);
  EXPECT_DOUBLE_EQ(in.gnss[2].covariance(2, 2), 1.0);
}

}  // namespace
}  // namespace semap::estimation
