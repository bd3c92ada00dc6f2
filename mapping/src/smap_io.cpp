#include "semap/mapping/smap_io.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <set>

#include "semap/mapping/atomic_file.hpp"

namespace semap::mapping {

static_assert(std::endian::native == std::endian::little,
              ".smap is little-endian and written with memcpy");

namespace {

constexpr std::array<char, 8> kMagic = {'S', 'E', 'M', 'A', 'P', 'M', 'A', 'P'};
constexpr std::uint32_t kLayerTag = 0x5259414c;   // "LAYR"
constexpr std::uint32_t kBlockTag = 0x4b434c42;   // "BLCK"
constexpr std::uint32_t kFooterTag = 0x444e4553;  // "SEND"
constexpr std::uint32_t kMaxParameters = 256;

std::uint32_t crc_of(std::span<const std::uint8_t> bytes) {
  return static_cast<std::uint32_t>(::crc32(0L, bytes.data(), static_cast<uInt>(bytes.size())));
}

class Writer {
 public:
  template <typename T>
  void put(T value) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void put_bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const std::uint8_t*>(data);
    bytes_.insert(bytes_.end(), p, p + size);
  }
  // Appends the CRC32 of everything written since `from`.
  void put_crc_since(std::size_t from) { put(crc_of(std::span(bytes_).subspan(from))); }
  std::size_t size() const { return bytes_.size(); }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

// Bounds-checked reads; every failure names the file and byte offset.
class Reader {
 public:
  Reader(std::span<const std::uint8_t> bytes, const std::string& name)
      : bytes_(bytes), name_(name) {}

  template <typename T>
  T get(const char* what) {
    need(sizeof(T), what);
    T value;
    std::memcpy(&value, bytes_.data() + offset_, sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  std::span<const std::uint8_t> take(std::size_t size, const char* what) {
    need(size, what);
    const auto out = bytes_.subspan(offset_, size);
    offset_ += size;
    return out;
  }
  // Reads a stored CRC32 and compares it with the CRC of bytes [from, here).
  void check_crc_since(std::size_t from, const std::string& what) {
    const std::uint32_t expected = crc_of(bytes_.subspan(from, offset_ - from));
    const std::size_t at = offset_;
    const auto stored = get<std::uint32_t>("CRC32");
    if (stored != expected) fail_at(at, what + ": CRC32 mismatch");
  }
  std::size_t offset() const { return offset_; }
  std::size_t remaining() const { return bytes_.size() - offset_; }
  [[noreturn]] void fail(const std::string& what) const { fail_at(offset_, what); }
  [[noreturn]] void fail_at(std::size_t at, const std::string& what) const {
    throw SmapError(name_ + ": byte offset " + std::to_string(at) + ": " + what);
  }

 private:
  void need(std::size_t size, const char* what) const {
    if (size > remaining()) {
      fail(std::string("truncated file: ") + what + " needs " + std::to_string(size) + " bytes, " +
           std::to_string(remaining()) + " left");
    }
  }

  std::span<const std::uint8_t> bytes_;
  const std::string& name_;
  std::size_t offset_ = 0;
};

// The header's named parameters, all written for every map. Older files of version 1 lack the
// bki.* ones unless SemanticMap built the map; a name missing from a file keeps its MapParams
// default. A name not listed here is an error: a setting this reader does not know could change
// what the evidence means, so a new setting needs a new version (docs/map-files.md).
template <typename Owner, typename T>
struct NamedParameter {
  const char* name;
  T Owner::*field;
};

constexpr std::array<NamedParameter<LogOddsParams, double>, 7> kLogOddsParameters = {{
    {"logodds.prob_hit", &LogOddsParams::prob_hit},
    {"logodds.prob_miss", &LogOddsParams::prob_miss},
    {"logodds.clamp_min", &LogOddsParams::clamp_min},
    {"logodds.clamp_max", &LogOddsParams::clamp_max},
    {"logodds.label_confidence", &LogOddsParams::label_confidence},
    {"logodds.label_spread", &LogOddsParams::label_spread},
    {"logodds.max_range", &LogOddsParams::max_range},
}};

// Alphabetical, the order files written so far have them in.
constexpr std::array<NamedParameter<MapParams, float>, 6> kBkiParameters = {{
    {"bki.ds_res", &MapParams::ds_res},
    {"bki.ell", &MapParams::ell},
    {"bki.free_res", &MapParams::free_res},
    {"bki.max_range", &MapParams::max_range},
    {"bki.sf2", &MapParams::sf2},
    {"bki.unknown_variance", &MapParams::unknown_variance},
}};

template <typename Table>
auto find_parameter(const Table& table, const std::string& name) {
  return std::find_if(table.begin(), table.end(), [&](const auto& p) { return name == p.name; });
}

void encode_header(Writer& w, const LayeredMap& map) {
  const MapParams& p = map.params();
  w.put_bytes(kMagic.data(), kMagic.size());
  w.put(kSmapVersion);
  w.put(static_cast<std::uint8_t>(p.method));
  w.put(static_cast<std::uint8_t>(p.block_depth));
  w.put(static_cast<std::uint16_t>(p.num_classes));
  w.put(static_cast<std::uint32_t>(p.channels()));
  w.put(static_cast<double>(p.resolution));
  w.put(static_cast<double>(p.prior));
  w.put(static_cast<std::uint32_t>(kLogOddsParameters.size() + kBkiParameters.size()));
  const auto put_named = [&](std::string_view name, double value) {
    w.put(static_cast<std::uint16_t>(name.size()));
    w.put_bytes(name.data(), name.size());
    w.put(value);
  };
  for (const auto& param : kLogOddsParameters) put_named(param.name, p.logodds.*param.field);
  for (const auto& param : kBkiParameters) put_named(param.name, p.*param.field);
  w.put(static_cast<std::uint32_t>(map.layers().size()));
  w.put_crc_since(0);
}

struct Header {
  MapParams params;
  std::uint32_t layers = 0;
};

Header decode_header(Reader& r) {
  const auto magic = r.take(kMagic.size(), "magic");
  if (!std::equal(magic.begin(), magic.end(), kMagic.begin())) {
    r.fail_at(0, "not a .smap file (bad magic)");
  }
  const auto version = r.get<std::uint32_t>("version");
  if (version != kSmapVersion) {
    r.fail_at(8, "unsupported .smap version " + std::to_string(version) +
                     " (this reader: " + std::to_string(kSmapVersion) + ")");
  }
  Header h;
  const auto method = r.get<std::uint8_t>("method");
  if (method > static_cast<std::uint8_t>(MapMethod::kLogOdds)) {
    r.fail("unknown map method " + std::to_string(method));
  }
  h.params.method = static_cast<MapMethod>(method);
  h.params.block_depth = r.get<std::uint8_t>("block depth");
  h.params.num_classes = r.get<std::uint16_t>("class count");
  const auto channels = r.get<std::uint32_t>("channel count");
  const auto resolution = r.get<double>("resolution");
  const auto prior = r.get<double>("prior");
  const auto count = r.get<std::uint32_t>("parameter count");
  if (count > kMaxParameters) r.fail("implausible parameter count " + std::to_string(count));
  std::vector<std::pair<std::string, double>> named;
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto length = r.get<std::uint16_t>("parameter name length");
    const auto name_bytes = r.take(length, "parameter name");
    const auto value = r.get<double>("parameter value");
    named.emplace_back(std::string(name_bytes.begin(), name_bytes.end()), value);
  }
  h.layers = r.get<std::uint32_t>("layer count");
  r.check_crc_since(0, "header");
  // Stored as doubles, held as floats: a value beyond float range is refused by name rather
  // than becoming inf.
  const auto to_float = [&](const std::string& name, double value) {
    if (!(std::isfinite(value) && std::fabs(value) <= std::numeric_limits<float>::max())) {
      r.fail("header: parameter " + name + " is not finite or beyond float range");
    }
    return static_cast<float>(value);
  };
  h.params.resolution = to_float("resolution", resolution);
  h.params.prior = to_float("prior", prior);
  std::set<std::string> seen;
  for (const auto& [name, value] : named) {
    if (!seen.insert(name).second) r.fail("header: parameter " + name + " twice");
    if (const auto lo = find_parameter(kLogOddsParameters, name); lo != kLogOddsParameters.end()) {
      if (!std::isfinite(value)) r.fail("header: parameter " + name + " is not finite");
      h.params.logodds.*lo->field = value;
    } else if (const auto bki = find_parameter(kBkiParameters, name); bki != kBkiParameters.end()) {
      h.params.*bki->field = to_float(name, value);
    } else {
      r.fail("header: unknown parameter '" + name + "' (known: logodds.* and bki.* settings)");
    }
  }
  try {
    h.params.validate();
  } catch (const std::invalid_argument& e) {
    r.fail(std::string("header: ") + e.what());
  }
  if (channels != static_cast<std::uint32_t>(h.params.channels())) {
    r.fail("header: " + std::to_string(channels) + " channels, method " +
           to_string(h.params.method) + " with " + std::to_string(h.params.num_classes) +
           " classes needs " + std::to_string(h.params.channels()));
  }
  return h;
}

std::vector<common::BlockIndex> sorted_keys(const EvidenceGrid& grid) {
  std::vector<common::BlockIndex> keys = grid.keys();
  std::sort(keys.begin(), keys.end(), [](const common::BlockIndex& a, const common::BlockIndex& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  });
  return keys;
}

}  // namespace

std::vector<std::uint8_t> encode_smap(const LayeredMap& map) {
  Writer w;
  encode_header(w, map);
  std::uint32_t total = 0;
  for (const auto& [source, grid] : map.layers()) {
    const std::size_t start = w.size();
    w.put(kLayerTag);
    w.put(source);
    w.put(grid.updates());
    w.put(static_cast<std::uint32_t>(grid.size()));
    w.put_crc_since(start);
    for (const common::BlockIndex& key : sorted_keys(grid)) {
      const std::vector<float> block = grid.find_block(key)->dense();
      const std::size_t block_start = w.size();
      w.put(kBlockTag);
      w.put(key.x);
      w.put(key.y);
      w.put(key.z);
      w.put(static_cast<std::uint32_t>(block.size()));
      w.put_bytes(block.data(), block.size() * sizeof(float));
      w.put_crc_since(block_start);
      ++total;
    }
  }
  w.put(kFooterTag);
  w.put(total);
  w.put_crc_since(0);
  return std::move(w.bytes());
}

SmapReadResult decode_smap(std::span<const std::uint8_t> bytes, const std::string& name,
                           const SmapReadOptions& options) {
  Reader r(bytes, name);
  const Header header = decode_header(r);
  SmapReadResult result(LayeredMap(header.params));
  const EvidenceGrid probe = result.map.make_grid();
  const std::size_t block_floats = probe.block_floats();
  // Smallest possible block record; bounds counts before anything is allocated.
  const std::size_t block_record = 5 * 4 + block_floats * sizeof(float) + 4;
  std::vector<float> values;  // one block, reused
  try {
    for (std::uint32_t layer = 0; layer < header.layers; ++layer) {
      const std::size_t start = r.offset();
      const std::string where = "layer " + std::to_string(layer);
      if (r.get<std::uint32_t>("layer tag") != kLayerTag) r.fail_at(start, where + ": bad tag");
      const auto source = r.get<std::uint32_t>("layer source");
      const auto updates = r.get<std::uint64_t>("layer update count");
      const auto blocks = r.get<std::uint32_t>("layer block count");
      r.check_crc_since(start, where);
      if (result.map.find_layer(source) != nullptr) {
        r.fail_at(start, where + ": source " + std::to_string(source) + " appears twice");
      }
      // Every block record has this size, so a count that cannot fit means the file was cut
      // inside this layer (the record's CRC vouches for the count). Salvage reads the blocks
      // that are there before reporting it.
      const std::size_t fit = r.remaining() / block_record;
      std::optional<std::string> cut;
      if (blocks > fit) {
        cut = where + ": " + std::to_string(blocks) + " blocks cannot fit in the " +
              std::to_string(r.remaining()) + " bytes left";
        if (!options.salvage) r.fail_at(start, *cut);
      }
      EvidenceGrid& grid = result.map.layer(source);
      grid.set_updates(updates);
      const std::uint32_t readable = cut ? static_cast<std::uint32_t>(fit) : blocks;
      for (std::uint32_t b = 0; b < readable; ++b) {
        const std::size_t block_start = r.offset();
        const std::string block_where =
            where + " (source " + std::to_string(source) + ") block " + std::to_string(b);
        if (r.get<std::uint32_t>("block tag") != kBlockTag) {
          r.fail_at(block_start, block_where + ": bad tag");
        }
        const common::BlockIndex key{r.get<std::int32_t>("block x"), r.get<std::int32_t>("block y"),
                                     r.get<std::int32_t>("block z")};
        const auto count = r.get<std::uint32_t>("block value count");
        if (count != block_floats) {
          r.fail_at(block_start, block_where + ": " + std::to_string(count) + " values, expected " +
                                     std::to_string(block_floats));
        }
        const auto raw = r.take(block_floats * sizeof(float), "block values");
        r.check_crc_since(block_start, block_where);
        if (!EvidenceGrid::in_range(key)) {
          r.fail_at(block_start, block_where + ": block key beyond the map's +-2^20 range");
        }
        values.resize(block_floats);
        std::memcpy(values.data(), raw.data(), raw.size());
        if (!std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); })) {
          r.fail_at(block_start, block_where + ": non-finite evidence");
        }
        if (grid.find_block(key) != nullptr) {
          r.fail_at(block_start, block_where + ": duplicate block key");
        }
        grid.put_block(key, values);
        ++result.blocks;
      }
      if (cut) r.fail_at(start, *cut);
    }
    const std::size_t footer = r.offset();
    if (r.get<std::uint32_t>("footer tag") != kFooterTag) r.fail_at(footer, "footer: bad tag");
    const auto total = r.get<std::uint32_t>("footer block count");
    if (total != result.blocks) {
      r.fail_at(footer, "footer: " + std::to_string(total) + " blocks announced, " +
                            std::to_string(result.blocks) + " read");
    }
    r.check_crc_since(0, "file");
    if (r.remaining() != 0) r.fail("trailing bytes after the footer");
  } catch (const SmapError& e) {
    if (!options.salvage) throw;
    result.complete = false;
    result.problem = e.what();
  }
  return result;
}

void write_smap(const std::filesystem::path& path, const LayeredMap& map) {
  // Temporaries of earlier writers to this path that were killed mid-write.
  remove_stale_temporaries(path);
  write_file_atomically(path, encode_smap(map));
}

SmapReadResult read_smap(const std::filesystem::path& path, const SmapReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SmapError(path.string() + ": cannot open");
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
  if (in.bad()) throw SmapError(path.string() + ": read error");
  return decode_smap(bytes, path.string(), options);
}

}  // namespace semap::mapping
