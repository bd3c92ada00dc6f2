/* Splits one serial byte stream carrying NMEA sentences and UBX frames, interleaved, into
 * frames, and resynchronises after garbage. Plain C99, fixed buffer, no allocation. */
#ifndef SEMAP_FIRMWARE_BRIDGE_GNSS_FRAMER_H
#define SEMAP_FIRMWARE_BRIDGE_GNSS_FRAMER_H

#include <stddef.h>
#include <stdint.h>

#include "semap/firmware_bridge/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Holds at least one maximal UBX frame plus slack. */
#define SEMAP_GNSS_FRAMER_CAPACITY 1024u

typedef enum SemapGnssFrameKind {
  SEMAP_GNSS_FRAME_NMEA = 0, /* '$' .. '\n' inclusive; checksum checked by semap_nmea_parse */
  SEMAP_GNSS_FRAME_UBX = 1   /* sync .. CK_B inclusive; checksum already verified */
} SemapGnssFrameKind;

/* Points into the framer's buffer: valid until the next push/next call. */
typedef struct SemapGnssFrame {
  SemapGnssFrameKind kind;
  const uint8_t* data;
  size_t len;
} SemapGnssFrame;

typedef struct SemapGnssFramerCounters {
  uint64_t bytes;         /* bytes pushed */
  uint64_t garbage_bytes; /* bytes skipped outside any frame */
  uint32_t nmea_frames;
  uint32_t ubx_frames;
  uint32_t bad_checksum; /* UBX Fletcher failures */
  uint32_t too_long;     /* NMEA over 82 chars without LF, UBX length over the limit */
  uint32_t truncated;    /* NMEA cut by a new start or a non-printable byte */
} SemapGnssFramerCounters;

typedef struct SemapGnssFramer {
  uint8_t buf[SEMAP_GNSS_FRAMER_CAPACITY];
  size_t begin; /* first unconsumed byte */
  size_t end;   /* one past the last stored byte */
  SemapGnssFramerCounters counters;
} SemapGnssFramer;

void semap_gnss_framer_init(SemapGnssFramer* f);

/* Stores up to `len` bytes (compacting first); returns how many were taken. Call
 * semap_gnss_framer_next until NEED_MORE before pushing the rest. */
size_t semap_gnss_framer_push(SemapGnssFramer* f, const uint8_t* data, size_t len);

/* Extracts the next event: OK with `out` set, NEED_MORE when the buffered bytes hold no complete
 * frame, or BAD_CHECKSUM / TOO_LONG / TRUNCATED for a rejected frame (already counted). */
SemapFbResult semap_gnss_framer_next(SemapGnssFramer* f, SemapGnssFrame* out);

#ifdef __cplusplus
}
#endif

#endif /* SEMAP_FIRMWARE_BRIDGE_GNSS_FRAMER_H */
