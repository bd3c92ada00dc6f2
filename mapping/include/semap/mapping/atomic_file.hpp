#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

namespace semap::mapping {

// Replaces `path` with `bytes` so that a crash leaves either the old or the new file, never a
// mix: the bytes go to a temporary file in the same directory, which is fsynced, renamed over
// `path`, and the directory is fsynced so the rename itself is durable.
// Throws std::runtime_error naming the path and the failing step.
void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

}  // namespace semap::mapping
