#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

namespace semap::mapping {

// Replaces `path` with `bytes` so that a crash leaves either the old or the new file, never a
// mix: the bytes go to a temporary file in the same directory, which is fsynced, renamed over
// `path`, and the directory is fsynced so the rename itself is durable.
// With `durable` false the fsyncs are skipped: still atomic against a crashing process, not
// against power loss (for scratch data such as tiles of a map that is saved properly later).
// Throws std::runtime_error naming the path and the failing step.
void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes,
                           bool durable = true);

}  // namespace semap::mapping
