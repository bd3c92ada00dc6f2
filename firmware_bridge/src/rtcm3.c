#include "semap/firmware_bridge/rtcm3.h"

static SemapFbResult result(SemapFbStatus status, int16_t field) {
  SemapFbResult r;
  r.status = status;
  r.field = field;
  return r;
}

uint32_t semap_rtcm3_crc24q(const uint8_t* data, size_t len) {
  uint32_t crc = 0;
  for (size_t i = 0; i < len; ++i) {
    crc ^= (uint32_t)data[i] << 16;
    for (int bit = 0; bit < 8; ++bit) {
      crc <<= 1;
      if (crc & 0x1000000u) crc ^= 0x1864CFBu;
    }
  }
  return crc & 0xFFFFFFu;
}

int semap_rtcm3_payload_length(const uint8_t* header) {
  if (header[0] != SEMAP_RTCM3_PREAMBLE || (header[1] & 0xFCu) != 0) return -1;
  return (int)(((unsigned)(header[1] & 0x03u) << 8) | header[2]);
}

SemapFbResult semap_rtcm3_check_frame(const uint8_t* frame, size_t len, SemapRtcm3FrameView* out) {
  if (len < SEMAP_RTCM3_OVERHEAD) return result(SEMAP_FB_TRUNCATED, -1);
  if (frame[0] != SEMAP_RTCM3_PREAMBLE) return result(SEMAP_FB_BAD_FIELD, 0);
  const int length = semap_rtcm3_payload_length(frame);
  if (length < 0) return result(SEMAP_FB_BAD_FIELD, 1);
  const size_t total = (size_t)length + SEMAP_RTCM3_OVERHEAD;
  if (len < total) return result(SEMAP_FB_TRUNCATED, -1);
  if (len > total) return result(SEMAP_FB_TOO_LONG, -1);
  const size_t body = (size_t)length + SEMAP_RTCM3_HEADER_LEN;
  const uint32_t crc =
      ((uint32_t)frame[body] << 16) | ((uint32_t)frame[body + 1] << 8) | (uint32_t)frame[body + 2];
  if (semap_rtcm3_crc24q(frame, body) != crc) return result(SEMAP_FB_BAD_CHECKSUM, -1);
  out->length = (uint16_t)length;
  out->payload = frame + SEMAP_RTCM3_HEADER_LEN;
  out->message_number =
      length >= 2 ? (uint16_t)(((unsigned)out->payload[0] << 4) | (out->payload[1] >> 4)) : 0u;
  return result(SEMAP_FB_OK, -1);
}
