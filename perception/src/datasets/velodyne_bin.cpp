#include "semap/perception/datasets/velodyne_bin.hpp"

#include <bit>
#include <cstring>
#include <fstream>

#include "semap/perception/datasets/dataset.hpp"

namespace semap::perception::datasets {

// The files are little-endian float32; a copy is only right on a little-endian host (x86-64 and
// arm64, every machine semap builds for).
static_assert(std::endian::native == std::endian::little, "velodyne .bin reading assumes LE");

std::vector<Eigen::Vector4f> read_velodyne_bin(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw DatasetError(path.string() + ": cannot open");
  const std::streamoff size = in.tellg();
  if (size < 0) throw DatasetError(path.string() + ": cannot read");
  std::vector<std::byte> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) {
    throw DatasetError(path.string() + ": cannot read");
  }
  return parse_velodyne_bin(bytes, path.string());
}

std::vector<Eigen::Vector4f> parse_velodyne_bin(std::span<const std::byte> bytes,
                                                const std::string& name) {
  constexpr std::size_t kPointBytes = 4 * sizeof(float);
  if (bytes.size() % kPointBytes != 0) {
    throw DatasetError(name + ": size " + std::to_string(bytes.size()) +
                       " bytes is not a multiple of 16 (x y z reflectance, float32 each)");
  }
  std::vector<Eigen::Vector4f> points(bytes.size() / kPointBytes);
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::memcpy(points[i].data(), bytes.data() + i * kPointBytes, kPointBytes);
  }
  return points;
}

}  // namespace semap::perception::datasets
