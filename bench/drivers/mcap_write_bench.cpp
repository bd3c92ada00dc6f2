// MCAP write speed per compression on a 10 MB mixed set: every 20th message camera-sized
// (60 kB of depth-image-like pixels, as the MCAP tests write), the rest IMU/CAN-sized. Figures:
// bytes/s of message payload and the file's size against the payload (counter "file_ratio").
#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mcap_test_recording.hpp"  // its depth-image-like payload
#include "semap/drivers/mcap_writer.hpp"

namespace {

namespace fs = std::filesystem;
namespace mcap = semap::drivers::mcap;
using Bytes = std::vector<std::uint8_t>;

void BM_McapWrite(benchmark::State& state) {
  const auto compression = static_cast<mcap::Compression>(state.range(0));
  std::vector<Bytes> set;
  std::size_t total = 0;
  for (std::uint32_t i = 0; total < 10'000'000; ++i) {
    set.push_back(mcap::test_recording::payload(i % 20 == 0 ? 60'000 : 64 + i % 200, i));
    total += set.back().size();
  }
  const fs::path path = fs::temp_directory_path() / "semap_mcap_write_bench.mcap";
  mcap::McapWriterOptions options;
  options.compression = compression;
  std::uintmax_t file_size = 0;
  for (auto _ : state) {
    mcap::McapWriter writer(path, options);
    const std::uint16_t camera = writer.add_channel(0, "/camera", "cdr");
    const std::uint16_t imu = writer.add_channel(0, "/imu", "cdr");
    for (std::uint32_t i = 0; i < set.size(); ++i) {
      writer.write(set[i].size() > 1000 ? camera : imu, i, i * 1'000'000ull, 0, set[i]);
    }
    writer.close();
    file_size = fs::file_size(path);
  }
  fs::remove(path);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * total));
  state.counters["file_ratio"] = static_cast<double>(file_size) / static_cast<double>(total);
  const std::string_view name = mcap::compression_name(compression);
  state.SetLabel(name.empty() ? "none" : std::string(name));
}
BENCHMARK(BM_McapWrite)
    ->Arg(static_cast<int>(mcap::Compression::kZstd))
    ->Arg(static_cast<int>(mcap::Compression::kLz4))
    ->Arg(static_cast<int>(mcap::Compression::kNone))
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
