// Decode throughput of the firmware_bridge codecs, in messages per second (items_per_second).
// Needed rates for scale: IMU 400 Hz x 3 frames = 1200 CAN frames/s; GNSS 10 Hz x 4 sentences.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "semap/firmware_bridge/can_imu.h"
#include "semap/firmware_bridge/gnss_encoder.hpp"
#include "semap/firmware_bridge/gnss_stream_decoder.hpp"
#include "semap/firmware_bridge/j1939.h"
#include "semap/firmware_bridge/nmea.h"
#include "semap/firmware_bridge/ubx.h"

namespace {

namespace fb = semap::firmware_bridge;

const std::string kGga = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n";
const std::string kRmc = "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\r\n";

semap::common::GnssFix sample_fix() {
  semap::common::GnssFix fix;
  fix.latitude_deg = 48.137;
  fix.longitude_deg = 11.575;
  fix.altitude_m = 520.0;
  fix.quality = semap::common::FixQuality::kRtkFixed;
  fix.satellites = 18;
  fix.covariance = Eigen::Vector3d(0.01, 0.01, 0.04).asDiagonal();
  fix.velocity_enu = Eigen::Vector3d(1.0, 2.0, 0.0);
  return fix;
}

void parse_sentence(benchmark::State& state, const std::string& sentence) {
  SemapNmeaSentence out;
  for (auto _ : state) {
    const SemapFbResult r = semap_nmea_parse(sentence.data(), sentence.size(), &out);
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(out);
  }
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(sentence.size()));
}

void BM_NmeaParseGga(benchmark::State& state) { parse_sentence(state, kGga); }
BENCHMARK(BM_NmeaParseGga);

void BM_NmeaParseRmc(benchmark::State& state) { parse_sentence(state, kRmc); }
BENCHMARK(BM_NmeaParseRmc);

// Whole serial path for NMEA: framer + parser + fix builder, 64 epochs of RMC/VTG/GST/GGA per
// buffer; items are sentences.
void BM_NmeaStreamDecode(benchmark::State& state) {
  std::string stream;
  for (int i = 0; i < 64; ++i) {
    for (const std::string& s :
         fb::encode_nmea_epoch(sample_fix(), 1'767'225'600'000 + i * 100, SEMAP_NMEA_TALKER_GN)) {
      stream += s;
    }
  }
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(stream.data()),
                                            stream.size());
  fb::GnssStreamDecoder decoder;
  std::vector<semap::common::GnssFix> fixes;
  fixes.reserve(64);
  for (auto _ : state) {
    fixes.clear();
    decoder.feed(bytes, semap::common::Stamp(1), fixes);
    benchmark::DoNotOptimize(fixes.data());
  }
  state.SetItemsProcessed(state.iterations() * 64 * 4);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(stream.size()));
}
BENCHMARK(BM_NmeaStreamDecode);

void BM_UbxNavPvtDecode(benchmark::State& state) {
  const std::vector<std::uint8_t> frame = fb::encode_ubx_epoch(sample_fix(), 1'767'225'600'000);
  SemapUbxNavPvt pvt;
  for (auto _ : state) {
    const SemapFbResult r = semap_ubx_decode_frame(frame.data(), frame.size(), &pvt);
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(pvt);
  }
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(frame.size()));
}
BENCHMARK(BM_UbxNavPvtDecode);

// Framer + NAV-PVT decode + GnssFix conversion over 64 frames per buffer.
void BM_UbxStreamDecode(benchmark::State& state) {
  std::vector<std::uint8_t> stream;
  for (int i = 0; i < 64; ++i) {
    const std::vector<std::uint8_t> f = fb::encode_ubx_epoch(sample_fix(), 1'767'225'600'000 + i);
    stream.insert(stream.end(), f.begin(), f.end());
  }
  fb::GnssStreamDecoder decoder;
  std::vector<semap::common::GnssFix> fixes;
  fixes.reserve(64);
  for (auto _ : state) {
    fixes.clear();
    decoder.feed(stream, semap::common::Stamp(1), fixes);
    benchmark::DoNotOptimize(fixes.data());
  }
  state.SetItemsProcessed(state.iterations() * 64);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(stream.size()));
}
BENCHMARK(BM_UbxStreamDecode);

// CAN IMU: CRC check, decode and sample assembly; items are frames (3 per sample).
void BM_CanImuClassicFrames(benchmark::State& state) {
  constexpr int kSamples = 256;
  std::vector<SemapCanFrame> frames(kSamples * 3);
  for (int i = 0; i < kSamples; ++i) {
    const double gyro[3] = {0.1, -0.2, 0.3};
    const double accel[3] = {0.5, -0.25, 9.81};
    SemapImuRaw raw;
    semap_can_imu_quantize(gyro, accel, static_cast<std::uint32_t>(i * 2500),
                           static_cast<std::uint8_t>(i), 0, &raw);
    semap_can_imu_encode(&raw, SEMAP_CAN_IMU_DEFAULT_BASE_ID, &frames[i * 3]);
  }
  SemapCanImuAssembler a;
  semap_can_imu_assembler_init(&a, SEMAP_CAN_IMU_DEFAULT_BASE_ID);
  SemapCanImuSample sample;
  for (auto _ : state) {
    for (const SemapCanFrame& f : frames) {
      benchmark::DoNotOptimize(semap_can_imu_assembler_push(&a, &f, &sample));
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(frames.size()));
  state.counters["samples_per_second"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * kSamples, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_CanImuClassicFrames);

void BM_CanImuFdFrames(benchmark::State& state) {
  constexpr int kSamples = 256;
  std::vector<SemapCanFrame> frames(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const double gyro[3] = {0.1, -0.2, 0.3};
    const double accel[3] = {0.5, -0.25, 9.81};
    SemapImuRaw raw;
    semap_can_imu_quantize(gyro, accel, static_cast<std::uint32_t>(i * 2500),
                           static_cast<std::uint8_t>(i), 0, &raw);
    semap_can_imu_encode_fd(&raw, SEMAP_CAN_IMU_DEFAULT_BASE_ID, &frames[i]);
  }
  SemapCanImuAssembler a;
  semap_can_imu_assembler_init(&a, SEMAP_CAN_IMU_DEFAULT_BASE_ID);
  SemapCanImuSample sample;
  for (auto _ : state) {
    for (const SemapCanFrame& f : frames) {
      benchmark::DoNotOptimize(semap_can_imu_assembler_push(&a, &f, &sample));
    }
  }
  state.SetItemsProcessed(state.iterations() * kSamples);
}
BENCHMARK(BM_CanImuFdFrames);

void BM_J1939ImuFrames(benchmark::State& state) {
  SemapJ1939AngularRate rate{};
  rate.yaw_dps = 10.0;
  SemapJ1939Acceleration acc{};
  acc.vertical_mps2 = 9.81;
  SemapCanFrame frames[2];
  semap_j1939_encode_angular_rate(&rate, 3, 0x80, &frames[0]);
  semap_j1939_encode_acceleration(&acc, 2, 0x80, &frames[1]);
  SemapJ1939ImuAssembler a;
  semap_j1939_imu_assembler_init(&a, 0x80);
  SemapJ1939AngularRate r;
  SemapJ1939Acceleration ac;
  for (auto _ : state) {
    benchmark::DoNotOptimize(semap_j1939_imu_assembler_push(&a, &frames[0], &r, &ac));
    benchmark::DoNotOptimize(semap_j1939_imu_assembler_push(&a, &frames[1], &r, &ac));
  }
  state.SetItemsProcessed(state.iterations() * 2);
}
BENCHMARK(BM_J1939ImuFrames);

}  // namespace

BENCHMARK_MAIN();
