/* Splits one serial byte stream into frames and resynchronises after garbage: NMEA sentences
 * (a doubled '$' tolerated), UBX frames of any length the protocol allows, RTCM3 frames, and
 * text lines that are not NMEA ('#' comments, '{' JSON). Plain C99, fixed buffer, no
 * allocation. */
#ifndef SEMAP_FIRMWARE_BRIDGE_GNSS_FRAMER_H
#define SEMAP_FIRMWARE_BRIDGE_GNSS_FRAMER_H

#include <stddef.h>
#include <stdint.h>

#include "semap/firmware_bridge/status.h"
#include "semap/firmware_bridge/ubx.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A frame that fits here is held whole until its checksum is verified, so one that fails costs
 * only its start bytes and whatever follows the cut is scanned again: NMEA (255 bytes), RTCM3
 * (1029), text lines and UBX frames up to this size. A longer UBX frame (NAV-SAT / NAV-SIG of
 * multi-band receivers reach several KiB, the protocol allows 65535 + 8) is skipped as it
 * arrives: its bytes are counted and run through the Fletcher checksum, not stored. That keeps
 * the framer at 2 KiB, fit for MCU firmware, where buffering the protocol maximum would take
 * 64 KiB. The price: a long frame that fails its checksum cannot be scanned again, so a long
 * length is trusted only behind a defined UBX message class. */
#define SEMAP_GNSS_FRAMER_CAPACITY 2048u

/* The longest '#' / '{' text line skipped whole; longer ones are TOO_LONG. */
#define SEMAP_GNSS_FRAMER_MAX_TEXT SEMAP_GNSS_FRAMER_CAPACITY

typedef enum SemapGnssFrameKind {
  SEMAP_GNSS_FRAME_NMEA = 0,        /* '$' .. '\n' inclusive (without a doubled '$'); checksum
                                       checked by semap_nmea_parse */
  SEMAP_GNSS_FRAME_UBX = 1,         /* sync .. CK_B inclusive; checksum already verified */
  SEMAP_GNSS_FRAME_UBX_SKIPPED = 2, /* UBX frame over the buffer, checksum verified while
                                       skipping it: `data` holds only its 6 header bytes */
  SEMAP_GNSS_FRAME_RTCM3 = 3,       /* preamble .. CRC inclusive; CRC-24Q already verified */
  SEMAP_GNSS_FRAME_TEXT = 4         /* '#' or '{' at a line start .. '\n' inclusive: not NMEA */
} SemapGnssFrameKind;

/* Points into the framer: valid until the next push/next call. */
typedef struct SemapGnssFrame {
  SemapGnssFrameKind kind;
  const uint8_t* data;
  size_t len;
  size_t wire_len; /* bytes the frame took in the stream (> len only for UBX_SKIPPED) */
} SemapGnssFrame;

typedef struct SemapGnssFramerCounters {
  uint64_t bytes;         /* bytes pushed */
  uint64_t garbage_bytes; /* bytes skipped outside any frame */
  uint32_t nmea_frames;
  uint32_t ubx_frames;   /* including the skipped ones */
  uint32_t ubx_skipped;  /* UBX frames longer than the buffer, skipped unbuffered */
  uint32_t rtcm3_frames; /* CRC-checked and skipped */
  uint32_t text_lines;   /* '#' / '{' lines skipped */
  uint32_t bad_checksum; /* UBX Fletcher and RTCM3 CRC-24Q failures */
  uint32_t too_long;     /* NMEA or text line without LF within its limit, implausible UBX
                            length */
  uint32_t truncated;    /* NMEA cut by a new start or a non-printable byte */
} SemapGnssFramerCounters;

/* State of a UBX frame being skipped unbuffered. */
typedef struct SemapGnssFramerSkip {
  uint8_t header[SEMAP_UBX_HEADER_LEN];
  uint8_t active;
  uint8_t ck_a, ck_b;         /* running Fletcher sums */
  uint8_t ck_seen;            /* checksum bytes received (0..2) */
  uint8_t ck_rx[2];           /* received CK_A, CK_B */
  uint32_t payload_remaining; /* payload bytes still to come */
} SemapGnssFramerSkip;

typedef struct SemapGnssFramer {
  uint8_t buf[SEMAP_GNSS_FRAMER_CAPACITY];
  size_t begin;       /* first unconsumed byte */
  size_t end;         /* one past the last stored byte */
  uint8_t line_start; /* the next byte starts a line (stream start, after LF or a frame) */
  SemapGnssFramerSkip skip;
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
