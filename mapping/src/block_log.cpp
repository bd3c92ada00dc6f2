#include "semap/mapping/block_log.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "semap/mapping/semantic_map.hpp"

namespace semap::mapping {

namespace {

constexpr char kMagic[8] = {'S', 'E', 'M', 'A', 'P', 'L', 'O', 'G'};
constexpr std::uint32_t kVersion = 1;
constexpr std::uint32_t kBlockRecord = 1;
constexpr std::uint32_t kCommitRecord = 2;
constexpr std::uint32_t kFrameRecord = 3;
// Magic, 4 u32 (version, method, cells per side, K), 4 f32 (resolution, prior, sf2, ell), CRC.
constexpr std::size_t kHeaderBytes = 8 + 4 * 4 + 4 * 4 + 4;
// Type and length before a record's payload, CRC after it.
constexpr std::size_t kFrameBytes = 4 + 4 + 4;
constexpr std::size_t kCommitPayload = 8;
constexpr std::size_t kFramePayload = 3 * 8;

std::uint32_t crc_of(std::span<const std::uint8_t> bytes) {
  return static_cast<std::uint32_t>(::crc32(0L, bytes.data(), static_cast<uInt>(bytes.size())));
}

std::size_t observed_words(const MapParams& p) {
  return (static_cast<std::size_t>(p.cells_per_block()) + 63) / 64;
}

std::size_t block_payload(const MapParams& p) {
  return 3 * 4 + 8 + static_cast<std::size_t>(p.cells_per_block()) * p.num_classes * 4 +
         observed_words(p) * 8;
}

class Writer {
 public:
  template <typename T>
  void put(const T& value) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  void put_bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const std::uint8_t*>(data);
    bytes.insert(bytes.end(), p, p + size);
  }
  std::vector<std::uint8_t> bytes;
};

template <typename T>
T get(std::span<const std::uint8_t> bytes, std::size_t at) {
  T value;
  std::memcpy(&value, bytes.data() + at, sizeof(T));
  return value;
}

std::vector<std::uint8_t> header_bytes(const MapParams& p) {
  Writer w;
  w.put_bytes(kMagic, sizeof kMagic);
  w.put(kVersion);
  w.put(static_cast<std::uint32_t>(p.method));
  w.put(static_cast<std::uint32_t>(p.cells_per_side()));
  w.put(static_cast<std::uint32_t>(p.num_classes));
  w.put(p.resolution);
  w.put(p.prior);
  w.put(p.sf2);
  w.put(p.ell);
  w.put(crc_of(w.bytes));
  return w.bytes;
}

// A record framed with its type, length and CRC.
std::vector<std::uint8_t> record_bytes(std::uint32_t type,
                                       const std::vector<std::uint8_t>& payload) {
  Writer w;
  w.put(type);
  w.put(static_cast<std::uint32_t>(payload.size()));
  w.put_bytes(payload.data(), payload.size());
  w.put(crc_of(w.bytes));
  return w.bytes;
}

std::vector<std::uint8_t> frame_record(const MapFrame& frame) {
  Writer payload;
  for (const double v : frame) payload.put(v);
  return record_bytes(kFrameRecord, payload.bytes);
}

void check_header(std::span<const std::uint8_t> bytes, const MapParams& p,
                  const std::string& name) {
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    throw BlockLogError(name + ": not a semap block log (no SEMAPLOG header)");
  }
  if (get<std::uint32_t>(bytes, kHeaderBytes - 4) != crc_of(bytes.first(kHeaderBytes - 4))) {
    throw BlockLogError(name + ": header CRC mismatch");
  }
  const auto field = [&](const char* what, auto stored, auto expected) {
    if (stored != expected) {
      throw BlockLogError(name + ": written for a map with " + what + " " + std::to_string(stored) +
                          ", this map has " + std::to_string(expected));
    }
  };
  field("version", get<std::uint32_t>(bytes, 8), kVersion);
  field("method", get<std::uint32_t>(bytes, 12), static_cast<std::uint32_t>(p.method));
  field("cells per block side", get<std::uint32_t>(bytes, 16),
        static_cast<std::uint32_t>(p.cells_per_side()));
  field("num_classes", get<std::uint32_t>(bytes, 20), static_cast<std::uint32_t>(p.num_classes));
  field("resolution", get<float>(bytes, 24), p.resolution);
  field("prior", get<float>(bytes, 28), p.prior);
  field("sf2", get<float>(bytes, 32), p.sf2);
  field("ell", get<float>(bytes, 36), p.ell);
}

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& step) {
  throw BlockLogError(path.string() + ": " + step + ": " + std::strerror(errno));
}

}  // namespace

BlockLogScan scan_block_log(std::span<const std::uint8_t> bytes, const MapParams& params,
                            const std::string& name) {
  check_header(bytes, params, name);
  BlockLogScan scan;
  scan.end = kHeaderBytes;
  // Blocks since the last commit, applied when the next commit arrives.
  std::unordered_map<common::BlockIndex, BlockLogEntry, common::BlockIndexHash> pending;
  std::optional<MapFrame> pending_frame;
  const std::size_t block_bytes = block_payload(params);
  std::size_t at = kHeaderBytes;
  while (at < bytes.size()) {
    const std::string where = name + ": record at byte " + std::to_string(at) + ": ";
    if (bytes.size() - at < kFrameBytes) {
      scan.damage = where + "torn (" + std::to_string(bytes.size() - at) + " bytes)";
      break;
    }
    const auto type = get<std::uint32_t>(bytes, at);
    const auto length = get<std::uint32_t>(bytes, at + 4);
    const std::size_t expected = type == kBlockRecord    ? block_bytes
                                 : type == kCommitRecord ? kCommitPayload
                                 : type == kFrameRecord  ? kFramePayload
                                                         : 0;
    if (expected == 0) {
      scan.damage = where + "unknown type " + std::to_string(type);
      break;
    }
    if (length != expected) {
      scan.damage =
          where + "length " + std::to_string(length) + ", expected " + std::to_string(expected);
      break;
    }
    if (bytes.size() - at < kFrameBytes + length) {
      scan.damage = where + "torn (" + std::to_string(bytes.size() - at) + " of " +
                    std::to_string(kFrameBytes + length) + " bytes)";
      break;
    }
    const std::size_t crc_at = at + 8 + length;
    if (get<std::uint32_t>(bytes, crc_at) != crc_of(bytes.subspan(at, 8 + length))) {
      scan.damage = where + "CRC mismatch";
      break;
    }
    if (type == kBlockRecord) {
      const common::BlockIndex index{get<std::int32_t>(bytes, at + 8),
                                     get<std::int32_t>(bytes, at + 12),
                                     get<std::int32_t>(bytes, at + 16)};
      const auto block_scan = get<std::uint64_t>(bytes, at + 20);
      pending[index] = {at, kFrameBytes + length, block_scan};
    } else if (type == kFrameRecord) {
      pending_frame = MapFrame{get<double>(bytes, at + 8), get<double>(bytes, at + 16),
                               get<double>(bytes, at + 24)};
    } else {
      for (const auto& [index, entry] : pending) scan.blocks[index] = entry;
      pending.clear();
      if (pending_frame) scan.frame = pending_frame;
      scan.committed_scans = get<std::uint64_t>(bytes, at + 8);
      ++scan.commits;
      scan.end = crc_at + 4;
    }
    at = crc_at + 4;
  }
  return scan;
}

BlockLog::BlockLog(std::filesystem::path path, const MapParams& params, bool durable)
    : path_(std::move(path)), params_(params), durable_(durable) {
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) fail(path_, "open");
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int error = errno;
    ::close(fd_);
    errno = error;
    fail(path_, "stat");
  }
  if (st.st_size == 0) {
    // A robot that boots with a full disk still maps: the header then goes in front of the
    // first record that fits, and the checkpoints report the failures until then.
    header_pending_ = true;
    try {
      write_at_end({});
      if (durable_) ::fsync(fd_);
    } catch (const BlockLogError&) {
    }
    return;
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(st.st_size));
  if (::pread(fd_, bytes.data(), bytes.size(), 0) != static_cast<ssize_t>(bytes.size())) {
    fail(path_, "read");
  }
  BlockLogScan scan = scan_block_log(bytes, params_, path_.string());
  blocks_ = std::move(scan.blocks);
  committed_scans_ = scan.committed_scans;
  frame_ = scan.frame;
  damage_ = std::move(scan.damage);
  end_ = scan.end;
  // Whatever follows the last commit is an unfinished checkpoint: new records replace it.
  if (end_ < bytes.size() && ::ftruncate(fd_, static_cast<off_t>(end_)) != 0) {
    fail(path_, "truncate");
  }
}

BlockLog::~BlockLog() {
  if (fd_ >= 0) ::close(fd_);
}

void BlockLog::write_at_end(std::span<const std::uint8_t> bytes) {
  std::vector<std::uint8_t> with_header;
  if (header_pending_) {
    with_header = header_bytes(params_);
    with_header.insert(with_header.end(), bytes.begin(), bytes.end());
    bytes = with_header;
  }
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n =
        ::pwrite(fd_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(end_ + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      // Disk full (ENOSPC), file size limit (EFBIG with SIGXFSZ ignored), I/O error: the part
      // that was written is cut off again, so the log ends with its last whole record and the
      // next append or a resume finds no torn bytes.
      const int error = n == 0 ? ENOSPC : errno;
      cut_back_to(end_);
      errno = error;
      fail(path_, "write");
    }
    done += static_cast<std::size_t>(n);
  }
  end_ += bytes.size();
  header_pending_ = false;
}

void BlockLog::cut_back_to(std::uint64_t end) {
  // Best effort: when even this fails the torn bytes stay beyond end_; the next record is
  // written over them and opening the log cuts whatever follows its last commit.
  if (::ftruncate(fd_, static_cast<off_t>(end)) == 0) end_ = end;
}

void BlockLog::append(const common::BlockIndex& index, std::uint64_t scan,
                      std::span<const float> evidence, std::span<const std::uint64_t> observed) {
  if (evidence.size() !=
          static_cast<std::size_t>(params_.cells_per_block()) * params_.num_classes ||
      observed.size() != observed_words(params_)) {
    throw std::invalid_argument("block log: block of the wrong size");
  }
  Writer payload;
  payload.put(index.x);
  payload.put(index.y);
  payload.put(index.z);
  payload.put(scan);
  payload.put_bytes(evidence.data(), evidence.size_bytes());
  payload.put_bytes(observed.data(), observed.size_bytes());
  const auto record = record_bytes(kBlockRecord, payload.bytes);
  std::lock_guard lock(mutex_);
  const auto it = blocks_.find(index);
  if (it != blocks_.end() && it->second.scan > scan) return;
  const std::uint64_t offset = end_;
  write_at_end(record);
  blocks_[index] = {offset, record.size(), scan};
}

void BlockLog::commit(std::uint64_t scans) {
  Writer payload;
  payload.put(scans);
  const auto commit = record_bytes(kCommitRecord, payload.bytes);
  std::lock_guard lock(mutex_);
  // The frame goes in front of the commit that makes it part of the map, in one write.
  std::vector<std::uint8_t> records;
  if (frame_ && frame_unwritten_) records = frame_record(*frame_);
  records.insert(records.end(), commit.begin(), commit.end());
  const std::uint64_t before = end_;
  const bool header_was_pending = header_pending_;
  write_at_end(records);
  if (durable_ && ::fdatasync(fd_) != 0) {
    // Not known to be on disk (ENOSPC and EIO can come this late): not a checkpoint. The
    // commit is taken back so that the log does not claim a map it may not hold.
    const int error = errno;
    cut_back_to(before);
    header_pending_ = header_was_pending;
    errno = error;
    fail(path_, "fsync");
  }
  committed_scans_ = scans;
  frame_unwritten_ = false;
}

void BlockLog::set_frame(const MapFrame& frame) {
  std::lock_guard lock(mutex_);
  // Written with the next commit (a frame counts from its commit on anyway), so recording
  // it never writes and cannot fail on a full disk.
  frame_ = frame;
  frame_unwritten_ = true;
}

std::optional<MapFrame> BlockLog::frame() const {
  std::lock_guard lock(mutex_);
  return frame_;
}

std::vector<std::uint8_t> BlockLog::read_record(const BlockLogEntry& entry) const {
  std::vector<std::uint8_t> bytes(entry.bytes);
  if (::pread(fd_, bytes.data(), bytes.size(), static_cast<off_t>(entry.offset)) !=
      static_cast<ssize_t>(bytes.size())) {
    fail(path_, "read");
  }
  if (get<std::uint32_t>(bytes, bytes.size() - 4) !=
      crc_of(std::span<const std::uint8_t>(bytes).first(bytes.size() - 4))) {
    throw BlockLogError(path_.string() + ": record at byte " + std::to_string(entry.offset) +
                        ": CRC mismatch on reading back");
  }
  return bytes;
}

bool BlockLog::read(const common::BlockIndex& index, std::vector<float>& evidence,
                    std::vector<std::uint64_t>& observed) const {
  std::vector<std::uint8_t> bytes;
  {
    std::lock_guard lock(mutex_);
    const auto it = blocks_.find(index);
    if (it == blocks_.end()) return false;
    bytes = read_record(it->second);
  }
  const std::size_t floats =
      static_cast<std::size_t>(params_.cells_per_block()) * params_.num_classes;
  evidence.resize(floats);
  observed.resize(observed_words(params_));
  // After the record's type and length: x, y, z and the scan (20 bytes).
  std::memcpy(evidence.data(), bytes.data() + 8 + 20, floats * 4);
  std::memcpy(observed.data(), bytes.data() + 8 + 20 + floats * 4, observed.size() * 8);
  return true;
}

bool BlockLog::load(const common::BlockIndex& index, SemanticMap& map) const {
  std::vector<float> evidence;
  std::vector<std::uint64_t> observed;
  if (!read(index, evidence, observed)) return false;
  map.restore_block(index, evidence, observed);
  return true;
}

std::size_t BlockLog::load_all(SemanticMap& map) const {
  std::size_t loaded = 0;
  for (const common::BlockIndex& index : blocks()) loaded += load(index, map) ? 1 : 0;
  return loaded;
}

bool BlockLog::compact(double factor) {
  std::lock_guard lock(mutex_);
  std::uint64_t live = kHeaderBytes;
  for (const auto& [index, entry] : blocks_) live += entry.bytes;
  if (static_cast<double>(end_) <= factor * static_cast<double>(live)) return false;
  const std::filesystem::path temp = path_.string() + ".compacting";
  // Read-write: after the rename this descriptor is the log's, so no reopen can fail.
  const int out = ::open(temp.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (out < 0) fail(temp, "open");
  std::unordered_map<common::BlockIndex, BlockLogEntry, common::BlockIndexHash> moved;
  std::uint64_t at = 0;
  try {
    const auto put = [&](std::span<const std::uint8_t> bytes) {
      errno = ENOSPC;  // what a short write without an error means
      if (::write(out, bytes.data(), bytes.size()) != static_cast<ssize_t>(bytes.size())) {
        fail(temp, "write");
      }
      at += bytes.size();
    };
    put(header_bytes(params_));
    if (frame_) put(frame_record(*frame_));
    for (const auto& [index, entry] : blocks_) {
      moved[index] = {at, entry.bytes, entry.scan};
      put(read_record(entry));
    }
    Writer payload;
    payload.put(committed_scans_);
    put(record_bytes(kCommitRecord, payload.bytes));
    if (::fsync(out) != 0) fail(temp, "fsync");
    if (::rename(temp.c_str(), path_.c_str()) != 0) fail(path_, "rename");
  } catch (const BlockLogError&) {
    // The log stays as it was, and the temporary goes: on a full disk it holds the space
    // the log needs to go on.
    ::close(out);
    ::unlink(temp.c_str());
    throw;
  }
  const int dir = ::open(path_.parent_path().empty() ? "." : path_.parent_path().c_str(),
                         O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
  ::close(fd_);
  fd_ = out;
  blocks_ = std::move(moved);
  end_ = at;
  frame_unwritten_ = false;  // the compacted log holds the frame and a commit
  header_pending_ = false;
  return true;
}

bool BlockLog::contains(const common::BlockIndex& index) const {
  std::lock_guard lock(mutex_);
  return blocks_.contains(index);
}

std::vector<common::BlockIndex> BlockLog::blocks() const {
  std::lock_guard lock(mutex_);
  std::vector<common::BlockIndex> out;
  out.reserve(blocks_.size());
  for (const auto& [index, entry] : blocks_) out.push_back(index);
  return out;
}

std::uint64_t BlockLog::committed_scans() const {
  std::lock_guard lock(mutex_);
  return committed_scans_;
}

std::uint64_t BlockLog::bytes() const {
  std::lock_guard lock(mutex_);
  return end_;
}

}  // namespace semap::mapping
