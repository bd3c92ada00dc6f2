#pragma once

// KITTI's Velodyne scan files (velodyne/NNNNNN.bin): per point x, y, z (metres, LiDAR frame:
// x forward, y left, z up) and reflectance, four float32 little-endian values.
#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace semap::perception::datasets {

// Throws DatasetError naming the file when it cannot be read or its size is not a multiple of
// 16 bytes (a truncated copy or another format).
std::vector<Eigen::Vector4f> read_velodyne_bin(const std::filesystem::path& path);

// The same from bytes already in memory; `name` starts the error message.
std::vector<Eigen::Vector4f> parse_velodyne_bin(std::span<const std::byte> bytes,
                                                const std::string& name);

}  // namespace semap::perception::datasets
