// CAN decoders: the input is a sequence of records [flags, id (4 bytes LE), len, payload...]
// fed to the semap assembler, the J1939 assembler and the kernel-frame converter.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "semap/firmware_bridge/can_imu_decoder.hpp"
#include "semap/firmware_bridge/linux_can.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace semap::firmware_bridge;
  CanImuDecoder semap_decoder(CanImuDecoderConfig{});
  CanImuDecoderConfig j1939;
  j1939.profile = ImuProfile::kJ1939;
  CanImuDecoder j1939_decoder(j1939);
  std::size_t pos = 0;
  std::uint64_t records = 0;
  while (pos + 6 <= size) {
    SemapCanFrame f{};
    const std::uint8_t flags = data[pos];
    std::uint32_t id;
    std::memcpy(&id, data + pos + 1, 4);
    f.extended = flags & 1u;
    f.fd = (flags >> 1) & 1u;
    f.id = f.extended ? (id & 0x1FFFFFFFu) : (id & 0x7FFu);
    const std::size_t max = f.fd ? SEMAP_CANFD_MAX_DLEN : SEMAP_CAN_MAX_DLEN;
    const std::size_t want = data[pos + 5] % (max + 1);
    pos += 6;
    const std::size_t len = want < size - pos ? want : size - pos;
    f.len = static_cast<std::uint8_t>(len);
    std::memcpy(f.data, data + pos, len);
    pos += len;
    ++records;
    semap_decoder.push(f, semap::common::Stamp(static_cast<std::int64_t>(records)));
    j1939_decoder.push(f, semap::common::Stamp(static_cast<std::int64_t>(records)));
  }
  const CanImuCounters a = semap_decoder.counters();
  const CanImuCounters b = j1939_decoder.counters();
  if (a.frames + a.unknown != records || b.frames + b.unknown != records) std::abort();
  if (a.samples > a.frames) std::abort();
  // The raw bytes as a kernel frame (only the two valid sizes are accepted).
  SemapCanFrame k;
  if (from_kernel_frame(data, size, k) && k.len > SEMAP_CANFD_MAX_DLEN) std::abort();
  return 0;
}
