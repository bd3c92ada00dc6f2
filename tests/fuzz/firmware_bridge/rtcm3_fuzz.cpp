// RTCM3 frame check and the framer's RTCM3 / long-UBX skipping over arbitrary bytes fed in
// chunks whose sizes come from the input. Every frame the framer hands out must pass the frame
// check of its protocol again, and the framer's byte accounting must add up.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "semap/firmware_bridge/gnss_framer.h"
#include "semap/firmware_bridge/nmea.h"
#include "semap/firmware_bridge/rtcm3.h"
#include "semap/firmware_bridge/ubx.h"

namespace {

void check_frame(const SemapGnssFrame& frame) {
  switch (frame.kind) {
    case SEMAP_GNSS_FRAME_RTCM3: {
      SemapRtcm3FrameView v;
      if (semap_rtcm3_check_frame(frame.data, frame.len, &v).status != SEMAP_FB_OK) std::abort();
      if (frame.len != v.length + SEMAP_RTCM3_OVERHEAD) std::abort();
      break;
    }
    case SEMAP_GNSS_FRAME_UBX: {
      SemapUbxFrameView v;
      const SemapFbResult r = semap_ubx_check_frame(frame.data, frame.len, &v);
      // semap_ubx_check_frame caps the payload at what it decodes; the framer takes more.
      if (r.status != SEMAP_FB_OK && r.status != SEMAP_FB_TOO_LONG) std::abort();
      if (frame.len > SEMAP_GNSS_FRAMER_CAPACITY) std::abort();
      break;
    }
    case SEMAP_GNSS_FRAME_UBX_SKIPPED:
      if (frame.len != SEMAP_UBX_HEADER_LEN || frame.wire_len <= SEMAP_GNSS_FRAMER_CAPACITY ||
          frame.data[0] != SEMAP_UBX_SYNC1 || frame.data[1] != SEMAP_UBX_SYNC2) {
        std::abort();
      }
      break;
    case SEMAP_GNSS_FRAME_NMEA:
      if (frame.len > SEMAP_NMEA_MAX_LENGTH || frame.data[0] != '$' ||
          frame.data[frame.len - 1] != '\n') {
        std::abort();
      }
      break;
    case SEMAP_GNSS_FRAME_TEXT:
      if ((frame.data[0] != '#' && frame.data[0] != '{') || frame.data[frame.len - 1] != '\n') {
        std::abort();
      }
      break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  SemapRtcm3FrameView view;
  const SemapFbResult r = semap_rtcm3_check_frame(data, size, &view);
  if (r.status >= SEMAP_FB_STATUS_COUNT) std::abort();
  if (r.status == SEMAP_FB_OK && size != view.length + SEMAP_RTCM3_OVERHEAD) std::abort();

  static SemapGnssFramer f;  // 2 KiB: keep it off the stack of the fuzzer thread
  semap_gnss_framer_init(&f);
  std::size_t pos = 0;
  std::uint64_t framed = 0;  // bytes handed out in frames
  for (;;) {
    SemapGnssFrame frame;
    const SemapFbResult next = semap_gnss_framer_next(&f, &frame);
    if (next.status == SEMAP_FB_NEED_MORE) {
      if (pos == size) break;
      const std::size_t chunk = 1 + data[pos] % 251;
      const std::size_t n = chunk < size - pos ? chunk : size - pos;
      const std::size_t taken = semap_gnss_framer_push(&f, data + pos, n);
      if (taken == 0 && f.end - f.begin == SEMAP_GNSS_FRAMER_CAPACITY) std::abort();  // stuck
      pos += taken;
      continue;
    }
    if (next.status >= SEMAP_FB_STATUS_COUNT || next.status == SEMAP_FB_UNKNOWN) std::abort();
    if (next.status == SEMAP_FB_OK) {
      check_frame(frame);
      framed += frame.wire_len;
    }
  }
  const SemapGnssFramerCounters& c = f.counters;
  if (c.bytes != size || c.garbage_bytes + framed > size) std::abort();
  if (c.ubx_skipped > c.ubx_frames) std::abort();
  return 0;
}
