/* RTCM 3 transport framing (RTCM 10403.x): recognised so that corrections interleaved on a GNSS
 * receiver's port can be checked and skipped, not decoded. Plain C99, no allocation. */
#ifndef SEMAP_FIRMWARE_BRIDGE_RTCM3_H
#define SEMAP_FIRMWARE_BRIDGE_RTCM3_H

#include <stddef.h>
#include <stdint.h>

#include "semap/firmware_bridge/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Preamble, then 6 reserved bits (zero) and a 10-bit payload length, the payload, CRC-24Q. */
#define SEMAP_RTCM3_PREAMBLE 0xD3u
#define SEMAP_RTCM3_HEADER_LEN 3u
#define SEMAP_RTCM3_CRC_LEN 3u
#define SEMAP_RTCM3_OVERHEAD (SEMAP_RTCM3_HEADER_LEN + SEMAP_RTCM3_CRC_LEN)
#define SEMAP_RTCM3_MAX_PAYLOAD 1023u
#define SEMAP_RTCM3_MAX_FRAME (SEMAP_RTCM3_MAX_PAYLOAD + SEMAP_RTCM3_OVERHEAD)

/* CRC-24Q (polynomial 0x1864CFB, initial value 0) over `len` bytes. */
uint32_t semap_rtcm3_crc24q(const uint8_t* data, size_t len);

/* Payload length from the 3 header bytes; -1 when the preamble or the reserved bits are wrong
 * (not the start of an RTCM3 frame). */
int semap_rtcm3_payload_length(const uint8_t* header);

typedef struct SemapRtcm3FrameView {
  uint16_t length;         /* payload bytes */
  uint16_t message_number; /* first 12 bits of the payload, 0 for an empty payload */
  const uint8_t* payload;
} SemapRtcm3FrameView;

/* Checks one whole frame: BAD_FIELD 0 for a wrong preamble, 1 for reserved bits set; TRUNCATED
 * when `len` is shorter than the frame, TOO_LONG when longer; BAD_CHECKSUM on a CRC mismatch. */
SemapFbResult semap_rtcm3_check_frame(const uint8_t* frame, size_t len, SemapRtcm3FrameView* out);

#ifdef __cplusplus
}
#endif

#endif /* SEMAP_FIRMWARE_BRIDGE_RTCM3_H */
