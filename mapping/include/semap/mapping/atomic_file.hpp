#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>

namespace semap::mapping {

// Replaces `path` with `bytes` so that a crash leaves either the old or the new file, never a
// mix: the bytes go to a temporary file in the same directory, which is fsynced, renamed over
// `path`, and the directory is fsynced so the rename itself is durable.
// Throws std::runtime_error naming the path and the failing step; on any failure the temporary
// is removed and `path` is untouched. A writer that is killed (SIGKILL, power cut) cannot remove
// its temporary: `.NAME.XXXXXX` stays next to the target until remove_stale_temporaries.
// The temporary is flock()ed while it is written.
void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

// Removes the temporaries write_file_atomically left for `path` when its writer died: names
// `.NAME.XXXXXX` in the same directory that no process holds locked and that were last written
// at least `min_age` ago (a writer between mkstemp and flock, or between close and rename, is
// young). Returns how many were removed; errors are ignored (best effort).
std::size_t remove_stale_temporaries(const std::filesystem::path& path,
                                     std::chrono::seconds min_age = std::chrono::seconds(10));

}  // namespace semap::mapping
