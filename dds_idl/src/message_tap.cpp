#include "semap/dds_idl/message_tap.hpp"

#include <dds/ddsi/ddsi_cdrstream.h>

#include <cstring>
#include <vector>

namespace semap::dds_idl {

namespace {
constexpr std::uint32_t kXcdr1 = 1;  // CDR_ENC_VERSION_1: what Cyclone 0.10 writes for final types
}  // namespace

void serialize_cdr(const void* sample, const dds_topic_descriptor_t& desc,
                   std::vector<std::uint8_t>& out) {
  dds_ostreamLE_t os;
  dds_ostreamLE_init(&os, 0, kXcdr1);
  dds_stream_writeLE(&os, static_cast<const char*>(sample), desc.m_ops);
  const std::uint32_t size = os.x.m_index;
  // DDSI wants the payload a multiple of 4 bytes; Cyclone says how much it padded in the low
  // bits of the encapsulation options (big-endian u16), as its serdata does.
  const std::uint32_t pad = (4 - (size % 4)) % 4;
  out.resize(4 + size + pad);
  out[0] = 0x00;
  out[1] = 0x01;  // CDR_LE
  out[2] = 0x00;
  out[3] = static_cast<std::uint8_t>(pad);
  if (size > 0) std::memcpy(out.data() + 4, os.x.m_buffer, size);
  std::memset(out.data() + 4 + size, 0, pad);
  dds_ostreamLE_fini(&os);
}

bool deserialize_cdr(std::span<const std::uint8_t> cdr, const dds_topic_descriptor_t& desc,
                     void* sample) {
  if (cdr.size() < 4 || cdr[0] != 0x00 || cdr[1] != 0x01) return false;  // CDR_LE only
  const std::uint32_t pad = cdr[3] & 3u;
  if (cdr.size() - 4 < pad) return false;
  const auto size = static_cast<std::uint32_t>(cdr.size() - 4 - pad);
  // The normaliser checks every length against the buffer (and may rewrite booleans), so it
  // works on a copy.
  std::vector<char> body(cdr.begin() + 4, cdr.begin() + 4 + size);
  std::uint32_t offset = 0;
  if (dds_stream_normalize_data(body.data(), &offset, size, false, kXcdr1, desc.m_ops) == nullptr) {
    return false;
  }
  dds_istream_t is;
  dds_istream_init(&is, size, body.data(), kXcdr1);
  dds_stream_read(&is, static_cast<char*>(sample), desc.m_ops);
  dds_istream_fini(&is);
  return true;
}

}  // namespace semap::dds_idl
