/* Decoder status shared by every firmware_bridge codec. Plain C99: usable in MCU firmware. */
#ifndef SEMAP_FIRMWARE_BRIDGE_STATUS_H
#define SEMAP_FIRMWARE_BRIDGE_STATUS_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Every decoder returns one of these so that drivers can count each failure kind. */
typedef enum SemapFbStatus {
  SEMAP_FB_OK = 0,
  SEMAP_FB_NEED_MORE,    /* accepted, but no complete message yet (assemblers, framers) */
  SEMAP_FB_BAD_CHECKSUM, /* CAN CRC-8, NMEA XOR checksum or UBX Fletcher-8 mismatch */
  SEMAP_FB_TOO_LONG,     /* NMEA sentence over 82 chars, UBX payload over the buffer */
  SEMAP_FB_TRUNCATED,    /* message ended (or a new one began) before it was complete */
  SEMAP_FB_UNKNOWN,      /* valid framing but an identifier/sentence/class we do not decode */
  SEMAP_FB_BAD_FIELD,    /* a field is malformed or out of range; SemapFbResult.field says which */
  SEMAP_FB_STATUS_COUNT
} SemapFbStatus;

/* Status plus the 0-based index of the offending field for SEMAP_FB_BAD_FIELD (NMEA: comma
 * separated field after the address; UBX/CAN: byte offset in the payload). */
typedef struct SemapFbResult {
  SemapFbStatus status;
  int16_t field;
} SemapFbResult;

/* Short lowercase name ("ok", "bad_checksum", ...) for logs and counters. */
const char* semap_fb_status_name(SemapFbStatus status);

#ifdef __cplusplus
}
#endif

#endif /* SEMAP_FIRMWARE_BRIDGE_STATUS_H */
