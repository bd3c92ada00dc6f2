#include "semap/dds_idl/block_cdr.hpp"

#include <cstring>
#include <string>
#include <type_traits>

#include "semap/dds_idl/converters.hpp"

namespace semap::dds_idl {

namespace {

// Encapsulation identifiers (big-endian on the wire): plain CDR and XCDR2, little-endian. A
// final struct of 1-, 2- and 4-byte members serialises to the same bytes in both. Cyclone
// byte-swaps a big-endian sample to native order before a reader sees it, so these are the
// only ones a little-endian host receives.
constexpr std::uint8_t kCdrLe = 0x01;
constexpr std::uint8_t kCdr2Le = 0x07;

// A bounds-checked cursor over the CDR body. Alignment is relative to the body's start, as
// CDR defines it; reads go through memcpy, so the bytes need no particular alignment in
// memory.
class CdrCursor {
 public:
  explicit CdrCursor(std::span<const std::uint8_t> body) : body_(body) {}

  std::size_t offset() const { return pos_; }
  std::size_t left() const { return body_.size() - pos_; }
  const char* failed_field() const { return failed_; }

  template <typename T>
  bool read(T& v, const char* field) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (!align(sizeof(T), field) || left() < sizeof(T)) return fail(field);
    std::memcpy(&v, body_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }

  // A sequence of T into `out` (resized, so same-length versions allocate nothing).
  template <typename T, typename U>
  bool read_sequence(std::vector<U>& out, const char* field) {
    static_assert(sizeof(T) == sizeof(U) && std::is_trivially_copyable_v<U>);
    std::uint32_t n = 0;
    if (!read(n, field)) return false;
    // Compared as counts, not bytes: n * sizeof(T) cannot overflow what is compared.
    if (!align(sizeof(T), field) || n > left() / sizeof(T)) return fail(field);
    out.resize(n);
    if (n > 0) std::memcpy(out.data(), body_.data() + pos_, std::size_t{n} * sizeof(T));
    pos_ += std::size_t{n} * sizeof(T);
    return true;
  }

  // A string: length including the terminating NUL, then the bytes. Only checked, not kept.
  bool skip_string(const char* field) {
    std::uint32_t n = 0;
    if (!read(n, field)) return false;
    if (n == 0 || n > left() || body_[pos_ + n - 1] != 0) return fail(field);
    pos_ += n;
    return true;
  }

 private:
  bool align(std::size_t a, const char* field) {
    const std::size_t aligned = (pos_ + a - 1) / a * a;
    if (aligned > body_.size()) return fail(field);
    pos_ = aligned;
    return true;
  }
  bool fail(const char* field) {
    failed_ = field;
    return false;
  }

  std::span<const std::uint8_t> body_;
  std::size_t pos_ = 0;
  const char* failed_ = "";
};

BlockCheck malformed(const BlockSnapshot& b, bool have_index, const std::string& what) {
  std::string where = "SemanticMapBlock";
  if (have_index) {
    where += " (" + std::to_string(b.index.x) + "," + std::to_string(b.index.y) + "," +
             std::to_string(b.index.z) + ")";
  }
  return {BlockReject::kMalformed, where + " CDR: " + what};
}

}  // namespace

BlockCheck read_block_cdr(std::span<const std::uint8_t> cdr, BlockSnapshot& out,
                          common::Stamp& stamp) {
  if (cdr.size() < 4) {
    return malformed(out, false, std::to_string(cdr.size()) + " bytes, no encapsulation header");
  }
  if (cdr[0] != 0 || (cdr[1] != kCdrLe && cdr[1] != kCdr2Le)) {
    return malformed(out, false,
                     "encapsulation " + std::to_string(cdr[0]) + "," + std::to_string(cdr[1]) +
                         " is not little-endian CDR or XCDR2");
  }
  CdrCursor c(cdr.subspan(4));
  bool have_index = false;
  const auto fail = [&] {
    return malformed(out, have_index,
                     std::string(c.failed_field()) + " at byte " + std::to_string(c.offset() + 4) +
                         " of " + std::to_string(cdr.size()) + " (truncated or bad length)");
  };
  // Field order of SemanticMapBlock_.idl: the key first, then the header.
  if (!c.read(out.index.x, "ix_") || !c.read(out.index.y, "iy_") || !c.read(out.index.z, "iz_")) {
    return fail();
  }
  have_index = true;
  msg::Time t{};
  if (!c.read(t.sec_, "header_.stamp_.sec") || !c.read(t.nanosec_, "header_.stamp_.nanosec") ||
      !c.skip_string("header_.frame_id_")) {
    return fail();
  }
  stamp = from_msg_time(t);
  if (!c.read(out.resolution, "resolution_") || !c.read(out.block_cells, "block_cells_") ||
      !c.read(out.num_classes, "num_classes_") || !c.read(out.version, "version_") ||
      !c.read_sequence<std::uint8_t>(out.state, "state_") ||
      !c.read_sequence<std::uint16_t>(out.argmax_class, "argmax_class_") ||
      !c.read_sequence<float>(out.variance, "variance_") ||
      !c.read_sequence<float>(out.evidence, "evidence_")) {
    return fail();
  }
  // A serialised sample may end in up to 3 bytes of padding (the header's options say how
  // many); anything more is not this type.
  if (c.left() > 3) {
    return malformed(out, true, std::to_string(c.left()) + " bytes after evidence_");
  }
  return {};
}

}  // namespace semap::dds_idl
