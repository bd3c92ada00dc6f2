#include "semap/estimation/oxts_reader.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "semap/estimation/evaluation.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {
namespace {

namespace fs = std::filesystem;

// A line in the KITTI format: lat lon alt roll pitch yaw vn ve vf vl vu ax ay az af al au
// wx wy wz wf wl wu pos_accuracy vel_accuracy navstat numsats posmode velmode orimode.
std::string line(double lat, double lon, double yaw, double ve) {
  std::ostringstream s;
  s.precision(12);
  s << lat << ' ' << lon << " 112.5 0.01 -0.02 " << yaw << " 0.5 " << ve
    << " 8.0 0.1 0.05 0.3 -0.1 9.81 0.3 -0.1 9.81 0.001 0.002 0.05 0.001 0.002 0.05 "
    << "0.4 0.05 4 11 5 5 6";
  return s.str();
}

class OxtsFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("semap_oxts_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "data");
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
  }
  fs::path dir_;
};

TEST_F(OxtsFolder, ReadsRecordsAndReportsBadOnes) {
  write("timestamps.txt",
        "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.074380937\n"
        "2011-09-26 13:02:26.184372000\n2011-09-26 13:02:26.294363000\n");
  write("data/0000000000.txt", line(49.015, 8.43, 1.2, 8.0) + "\n");
  write("data/0000000001.txt", line(49.01501, 8.43001, 1.21, 8.1) + "\n");
  write("data/0000000002.txt", "49.0 8.4 112.0 0.0 oops\n");
  write("data/0000000003.txt", line(49.01502, 8.43002, 1.22, 8.2) + "\n");
  const OxtsData d = read_oxts_folder(dir_);
  ASSERT_EQ(d.records.size(), 3u);
  ASSERT_EQ(d.errors.size(), 1u);
  EXPECT_NE(d.errors[0].find("0000000002.txt:1"), std::string::npos) << d.errors[0];
  EXPECT_NE(d.errors[0].find("field 5 (pitch)"), std::string::npos) << d.errors[0];
  const OxtsRecord& r = d.records[1];
  EXPECT_DOUBLE_EQ(r.latitude_deg, 49.01501);
  EXPECT_DOUBLE_EQ(r.yaw, 1.21);
  EXPECT_DOUBLE_EQ(r.velocity_enu.x(), 8.1);  // ve
  EXPECT_DOUBLE_EQ(r.velocity_enu.y(), 0.5);  // vn
  EXPECT_DOUBLE_EQ(r.accel.z(), 9.81);
  EXPECT_DOUBLE_EQ(r.gyro.z(), 0.05);
  EXPECT_EQ(r.satellites, 11);
  EXPECT_EQ(r.stamp.ns - d.records[0].stamp.ns, 109991492);

  const DriveData in = oxts_to_inputs(d, 0.5, 1);
  ASSERT_EQ(in.imu.size(), 3u);
  ASSERT_EQ(in.gnss.size(), 3u);
  EXPECT_NEAR(in.origin.latitude_deg, 49.015, 1e-12);
  EXPECT_LT(in.truth[0].state.position.norm(), 1e-9);
  EXPECT_NEAR(in.truth[1].state.position.y(), 0.00001 * 111200.0, 0.5);  // ~1.1 m north
  EXPECT_NEAR(yaw_of(in.truth[2].state.rotation), 1.22, 1e-9);
}

// A consistent 60 s drive written in the OXTS format (rest, straight acceleration, left circle)
// runs through reader, conversion and estimator end to end.
TEST_F(OxtsFolder, FilterRunsOnOxtsDrive) {
  std::ofstream stamps(dir_ / "timestamps.txt");
  for (int i = 0; i < 600; ++i) {
    const double t = 0.1 * i;
    double v = 0, ax = 0, w = 0, x = 0, y = 0, yaw = 0;
    if (t >= 3.0 && t < 8.0) {
      v = 2.0 * (t - 3.0);
      ax = 2.0;
      x = (t - 3.0) * (t - 3.0);
    } else if (t >= 8.0) {
      v = 10.0;
      w = 0.2;
      yaw = w * (t - 8.0);
      x = 25.0 + 50.0 * std::sin(yaw);
      y = 50.0 * (1.0 - std::cos(yaw));
    }
    const int ms = i * 100;
    char stamp[64];
    std::snprintf(stamp, sizeof(stamp), "2011-09-26 13:%02d:%02d.%03d000000\n", 2 + ms / 60000,
                  (ms / 1000) % 60, ms % 1000);
    stamps << stamp;
    std::ostringstream line;
    line.precision(12);
    line << 49.0 + y / 111200.0 << ' ' << 8.4 + x / (111320.0 * std::cos(49.0 * M_PI / 180.0))
         << " 110 0 0 " << yaw << ' ' << v * std::sin(yaw) << ' ' << v * std::cos(yaw) << ' ' << v
         << " 0 0 " << ax << ' ' << v * w << " 9.80665 " << ax << ' ' << v * w << " 9.80665 0 0 "
         << w << " 0 0 " << w << " 0.3 0.05 4 10 4 4 0";
    char name[32];
    std::snprintf(name, sizeof(name), "data/%010d.txt", i);
    write(name, line.str() + "\n");
  }
  stamps.close();
  const OxtsData d = read_oxts_folder(dir_);
  ASSERT_EQ(d.records.size(), 600u);
  EXPECT_TRUE(d.errors.empty());
  const DriveData in = oxts_to_inputs(d, 0.5, 3);
  EstimatorConfig config;
  config.imu_limits.max_dt_s = 0.25;  // 10 Hz OXTS
  config.init.yaw_rad = 2.0;          // 115 deg off
  EvaluationOptions options;
  options.metrics_after_s = 20.0;
  const EvaluationRun run = run_evaluation(in, config, options);
  EXPECT_LT(run.metrics.ate_rmse_m, 0.5);
  EXPECT_LT(run.metrics.heading_rmse_deg, 3.0);
  EXPECT_EQ(run.counters.imu.rejected(), 0u);
}

TEST_F(OxtsFolder, MissingFolderThrows) {
  EXPECT_THROW(read_oxts_folder(dir_ / "nope"), std::runtime_error);
}

TEST(OxtsParser, RejectsMalformedLinesWithField) {
  std::string error;
  EXPECT_FALSE(parse_oxts_line("1 2 3", error).has_value());
  EXPECT_NE(error.find("got 3"), std::string::npos);
  EXPECT_FALSE(parse_oxts_line(line(49, 8, 0, 0) + " 7", error).has_value());
  EXPECT_FALSE(parse_oxts_line(line(95, 8, 0, 0), error).has_value());
  EXPECT_FALSE(parse_oxts_line("nan" + line(49, 8, 0, 0).substr(2), error).has_value());
  EXPECT_TRUE(parse_oxts_line(line(49, 8, 0, 0) + "\r\n", error).has_value());
  EXPECT_FALSE(parse_kitti_timestamp("2011-09-26T13:02:25").has_value());
  EXPECT_FALSE(parse_kitti_timestamp("2011-13-26 13:02:25.1").has_value());
  const auto t = parse_kitti_timestamp("1970-01-01 00:00:01.5");
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(t->ns, 1'500'000'000);
}

// Found by the OXTS fuzz target under UBSan: seconds * 1e9 overflowed int64 for year 7182.
TEST(OxtsParser, TimestampOutOfRangeNamesTheField) {
  std::string error;
  EXPECT_FALSE(parse_kitti_timestamp("7182-01-01 00:00:00", error).has_value());
  EXPECT_NE(error.find("year 7182"), std::string::npos) << error;
  EXPECT_FALSE(parse_kitti_timestamp("9999-12-31 23:59:59.999999999", error).has_value());
  EXPECT_NE(error.find("year"), std::string::npos) << error;
  EXPECT_FALSE(parse_kitti_timestamp("1969-12-31 23:59:59", error).has_value());
  EXPECT_NE(error.find("year 1969"), std::string::npos) << error;
  EXPECT_FALSE(parse_kitti_timestamp("2011-09-26 24:00:00", error).has_value());
  EXPECT_NE(error.find("hour 24"), std::string::npos) << error;
  EXPECT_FALSE(parse_kitti_timestamp("2011-09-26 13:-1:25", error).has_value());
  EXPECT_NE(error.find("minute"), std::string::npos) << error;
  EXPECT_FALSE(parse_kitti_timestamp("2011-02-30 13:02:25", error).has_value());
  EXPECT_NE(error.find("day 30"), std::string::npos) << error;
  // The int64 nanosecond clock ends at 2262-04-11 23:47:16.854775807 UTC.
  EXPECT_FALSE(parse_kitti_timestamp("2262-12-31 00:00:00", error).has_value());
  EXPECT_NE(error.find("2262"), std::string::npos) << error;
  const auto last = parse_kitti_timestamp("2262-04-11 23:47:16.854775807", error);
  ASSERT_TRUE(last.has_value()) << error;
  EXPECT_EQ(last->ns, std::numeric_limits<std::int64_t>::max());
  EXPECT_FALSE(parse_kitti_timestamp("2262-04-11 23:47:16.854775808", error).has_value());
  // 2000 is a leap year, 1900-style centuries are not (2100).
  EXPECT_TRUE(parse_kitti_timestamp("2000-02-29 00:00:00", error).has_value()) << error;
  EXPECT_FALSE(parse_kitti_timestamp("2100-02-29 00:00:00", error).has_value());
  // 2011-09-26 13:02:25 UTC = 15243 days and 46945 s after the epoch.
  const auto kitti = parse_kitti_timestamp("2011-09-26 13:02:25.964389445", error);
  ASSERT_TRUE(kitti.has_value()) << error;
  EXPECT_EQ(kitti->ns, (15243LL * 86400 + 46945) * 1'000'000'000LL + 964389445);
}

}  // namespace
}  // namespace semap::estimation
