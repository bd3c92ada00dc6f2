#include "semap/firmware_bridge/gnss_framer.h"

#include <string.h>

#include "bytes.h"
#include "semap/firmware_bridge/nmea.h"
#include "semap/firmware_bridge/rtcm3.h"
#include "semap/firmware_bridge/ubx.h"

#define SEMAP_NMEA_ADDRESS_END 6u /* '$' + 5 address chars */

/* Internal verdict of a frame reader: the bytes at the cursor were consumed or skipped, look
 * again (never returned to the caller). */
#define SEMAP_FRAMER_AGAIN SEMAP_FB_STATUS_COUNT

static SemapFbResult result(SemapFbStatus status) {
  SemapFbResult r;
  r.status = status;
  r.field = -1;
  return r;
}

void semap_gnss_framer_init(SemapGnssFramer* f) {
  memset(f, 0, sizeof *f);
  f->line_start = 1;
}

size_t semap_gnss_framer_push(SemapGnssFramer* f, const uint8_t* data, size_t len) {
  if (f->begin > 0) {
    memmove(f->buf, f->buf + f->begin, f->end - f->begin);
    f->end -= f->begin;
    f->begin = 0;
  }
  const size_t room = SEMAP_GNSS_FRAMER_CAPACITY - f->end;
  const size_t take = len < room ? len : room;
  memcpy(f->buf + f->end, data, take);
  f->end += take;
  f->counters.bytes += take;
  return take;
}

/* "$" then 4 of [A-Z0-9] and one of [A-Z0-9,] ("$GPGGA", "$PUBX,"). Requiring a plausible
 * address keeps a '$' inside binary UBX data from being reported as a truncated sentence. */
static int address_char(uint8_t c, size_t index) {
  if ((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9')) return 1;
  return index == SEMAP_NMEA_ADDRESS_END - 1 && c == ',';
}

static void skip(SemapGnssFramer* f, size_t n, int garbage) {
  if (n == 0) return;
  f->line_start = f->buf[f->begin + n - 1] == '\n';
  f->begin += n;
  if (garbage) f->counters.garbage_bytes += n;
}

static void emit(SemapGnssFramer* f, SemapGnssFrameKind kind, size_t len, SemapGnssFrame* out) {
  out->kind = kind;
  out->data = f->buf + f->begin;
  out->len = len;
  out->wire_len = len;
  skip(f, len, 0);
  f->line_start = 1;
}

/* '#' and '{' start a text line only where a line can start: at the beginning of the stream,
 * after a LF or right after a frame. Elsewhere they are noise like any other byte. */
static int frame_start(const SemapGnssFramer* f, const uint8_t* b, size_t i) {
  const uint8_t c = b[i];
  if (c == '$' || c == SEMAP_UBX_SYNC1 || c == SEMAP_RTCM3_PREAMBLE) return 1;
  if (c != '#' && c != '{') return 0;
  return i == 0 ? f->line_start : b[i - 1] == '\n';
}

static SemapFbResult nmea(SemapGnssFramer* f, const uint8_t* b, size_t n, SemapGnssFrame* out) {
  if (n < 2) return result(SEMAP_FB_NEED_MORE);
  if (b[1] == '$') {
    /* Some receivers (ST Teseo) start every sentence with "$$": the first one is not data. */
    skip(f, 1, 0);
    return result(SEMAP_FRAMER_AGAIN);
  }
  size_t k = 1;
  while (k < n && k < SEMAP_NMEA_ADDRESS_END && address_char(b[k], k)) ++k;
  if (k < SEMAP_NMEA_ADDRESS_END) {
    if (k == n) return result(SEMAP_FB_NEED_MORE);
    skip(f, 1, 1);
    return result(SEMAP_FRAMER_AGAIN);
  }
  const size_t limit = n < SEMAP_NMEA_MAX_LENGTH ? n : SEMAP_NMEA_MAX_LENGTH;
  for (; k < limit; ++k) {
    const uint8_t c = b[k];
    if (c == '\n') {
      emit(f, SEMAP_GNSS_FRAME_NMEA, k + 1, out);
      f->counters.nmea_frames++;
      return result(SEMAP_FB_OK);
    }
    /* CR belongs to a sentence only as the first half of its CR LF ending. */
    const int stray_cr = c == '\r' && k + 1 < n && b[k + 1] != '\n';
    if (c == '$' || stray_cr || (c != '\r' && (c < 0x20u || c > 0x7Eu))) {
      skip(f, k, 0);
      f->counters.truncated++;
      return result(SEMAP_FB_TRUNCATED);
    }
  }
  if (n < SEMAP_NMEA_MAX_LENGTH) return result(SEMAP_FB_NEED_MORE);
  /* Drop only the '$': the rest of the overlong line is skipped as garbage. */
  skip(f, 1, 0);
  f->counters.too_long++;
  return result(SEMAP_FB_TOO_LONG);
}

/* Message classes of the u-blox protocol (NAV RXM INF ACK CFG UPD MON AID TIM ESF MGA LOG SEC
 * HNR NAV2): a length too long to buffer is believed only behind one of them. */
static int known_ubx_class(uint8_t c) {
  static const uint8_t kClasses[] = {0x01, 0x02, 0x04, 0x05, 0x06, 0x09, 0x0A, 0x0B,
                                     0x0D, 0x10, 0x13, 0x21, 0x27, 0x28, 0x29};
  for (size_t i = 0; i < sizeof kClasses; ++i) {
    if (kClasses[i] == c) return 1;
  }
  return 0;
}

static SemapFbResult ubx(SemapGnssFramer* f, const uint8_t* b, size_t n, SemapGnssFrame* out) {
  if (n < 2) return result(SEMAP_FB_NEED_MORE);
  if (b[1] != SEMAP_UBX_SYNC2) {
    skip(f, 1, 1);
    return result(SEMAP_FRAMER_AGAIN);
  }
  if (n < SEMAP_UBX_HEADER_LEN) return result(SEMAP_FB_NEED_MORE);
  const size_t length = semap_get_u16(b + 4);
  const size_t total = length + SEMAP_UBX_OVERHEAD;
  if (total > SEMAP_GNSS_FRAMER_CAPACITY) {
    if (!known_ubx_class(b[2])) {
      skip(f, 2, 0);
      f->counters.too_long++;
      return result(SEMAP_FB_TOO_LONG);
    }
    SemapGnssFramerSkip* s = &f->skip;
    memcpy(s->header, b, SEMAP_UBX_HEADER_LEN);
    s->ck_a = 0;
    s->ck_b = 0;
    for (size_t i = 2; i < SEMAP_UBX_HEADER_LEN; ++i) {
      s->ck_a = (uint8_t)(s->ck_a + b[i]);
      s->ck_b = (uint8_t)(s->ck_b + s->ck_a);
    }
    s->ck_seen = 0;
    s->payload_remaining = (uint32_t)length;
    s->active = 1;
    skip(f, SEMAP_UBX_HEADER_LEN, 0);
    return result(SEMAP_FRAMER_AGAIN);
  }
  if (n < total) return result(SEMAP_FB_NEED_MORE);
  uint8_t a, c;
  semap_ubx_checksum(b + 2, length + 4u, &a, &c);
  if (a != b[total - 2] || c != b[total - 1]) {
    /* Skip only the sync chars: a frame cut short hides the start of the next one. */
    skip(f, 2, 0);
    f->counters.bad_checksum++;
    return result(SEMAP_FB_BAD_CHECKSUM);
  }
  emit(f, SEMAP_GNSS_FRAME_UBX, total, out);
  f->counters.ubx_frames++;
  return result(SEMAP_FB_OK);
}

/* Consumes the buffered bytes of a UBX frame being skipped. */
static SemapFbResult continue_skip(SemapGnssFramer* f, SemapGnssFrame* out) {
  SemapGnssFramerSkip* s = &f->skip;
  const uint8_t* b = f->buf + f->begin;
  const size_t n = f->end - f->begin;
  size_t i = 0;
  for (; i < n && s->payload_remaining > 0; ++i, --s->payload_remaining) {
    s->ck_a = (uint8_t)(s->ck_a + b[i]);
    s->ck_b = (uint8_t)(s->ck_b + s->ck_a);
  }
  for (; i < n && s->payload_remaining == 0 && s->ck_seen < 2; ++i) s->ck_rx[s->ck_seen++] = b[i];
  skip(f, i, 0);
  if (s->ck_seen < 2) return result(SEMAP_FB_NEED_MORE);
  s->active = 0;
  if (s->ck_rx[0] != s->ck_a || s->ck_rx[1] != s->ck_b) {
    f->counters.bad_checksum++;
    return result(SEMAP_FB_BAD_CHECKSUM);
  }
  out->kind = SEMAP_GNSS_FRAME_UBX_SKIPPED;
  out->data = s->header;
  out->len = SEMAP_UBX_HEADER_LEN;
  out->wire_len = (size_t)semap_get_u16(s->header + 4) + SEMAP_UBX_OVERHEAD;
  f->counters.ubx_frames++;
  f->counters.ubx_skipped++;
  f->line_start = 1;
  return result(SEMAP_FB_OK);
}

/* RTCM3 message numbers in use (RTCM 10403.3: 1001-1300 and SSR up to 1399; 4001-4095
 * proprietary) or an empty frame. A preamble byte in noise passes the reserved bits one time in
 * 64; this check rejects 9 in 10 of those at once instead of waiting for up to 1029 bytes to
 * fail the CRC, which would hold back the frames behind it. */
static int plausible_rtcm3(int length, const uint8_t* b) {
  if (length == 0) return 1;
  if (length < 2) return 0;
  const unsigned number = ((unsigned)b[3] << 4) | (b[4] >> 4);
  return (number >= 1001u && number <= 1399u) || (number >= 4001u && number <= 4095u);
}

static SemapFbResult rtcm3(SemapGnssFramer* f, const uint8_t* b, size_t n, SemapGnssFrame* out) {
  if (n < SEMAP_RTCM3_HEADER_LEN) return result(SEMAP_FB_NEED_MORE);
  const int length = semap_rtcm3_payload_length(b);
  if (length >= 2 && n < SEMAP_RTCM3_HEADER_LEN + 2) return result(SEMAP_FB_NEED_MORE);
  if (length < 0 || !plausible_rtcm3(length, b)) {
    skip(f, 1, 1);
    return result(SEMAP_FRAMER_AGAIN);
  }
  const size_t total = (size_t)length + SEMAP_RTCM3_OVERHEAD;
  if (n < total) return result(SEMAP_FB_NEED_MORE);
  SemapRtcm3FrameView view;
  if (semap_rtcm3_check_frame(b, total, &view).status != SEMAP_FB_OK) {
    /* As for UBX: skip the preamble only and look for frames inside. */
    skip(f, 1, 0);
    f->counters.bad_checksum++;
    return result(SEMAP_FB_BAD_CHECKSUM);
  }
  emit(f, SEMAP_GNSS_FRAME_RTCM3, total, out);
  f->counters.rtcm3_frames++;
  return result(SEMAP_FB_OK);
}

/* A text line is printable ASCII, TAB, CR or UTF-8 (bytes >= 0x80) up to LF; it may quote a
 * sentence ("# one $GPGSV with a bad checksum"). A control byte means the '#' / '{' was noise:
 * only it is skipped, as garbage, and the bytes after it are scanned again. */
static SemapFbResult text(SemapGnssFramer* f, const uint8_t* b, size_t n, SemapGnssFrame* out) {
  const size_t limit = n < SEMAP_GNSS_FRAMER_MAX_TEXT ? n : SEMAP_GNSS_FRAMER_MAX_TEXT;
  for (size_t k = 1; k < limit; ++k) {
    const uint8_t c = b[k];
    if (c == '\n') {
      emit(f, SEMAP_GNSS_FRAME_TEXT, k + 1, out);
      f->counters.text_lines++;
      return result(SEMAP_FB_OK);
    }
    const int control = c < 0x20u && c != '\t' && c != '\r';
    if (control || c == 0x7Fu) {
      skip(f, 1, 1);
      return result(SEMAP_FRAMER_AGAIN);
    }
  }
  if (n < SEMAP_GNSS_FRAMER_MAX_TEXT) return result(SEMAP_FB_NEED_MORE);
  skip(f, 1, 0);
  f->counters.too_long++;
  return result(SEMAP_FB_TOO_LONG);
}

SemapFbResult semap_gnss_framer_next(SemapGnssFramer* f, SemapGnssFrame* out) {
  for (;;) {
    if (f->skip.active) return continue_skip(f, out);
    const uint8_t* b = f->buf + f->begin;
    size_t n = f->end - f->begin;
    size_t i = 0;
    while (i < n && !frame_start(f, b, i)) ++i;
    skip(f, i, 1);
    b += i;
    n -= i;
    if (n == 0) return result(SEMAP_FB_NEED_MORE);

    SemapFbResult r;
    switch (b[0]) {
      case '$':
        r = nmea(f, b, n, out);
        break;
      case SEMAP_UBX_SYNC1:
        r = ubx(f, b, n, out);
        break;
      case SEMAP_RTCM3_PREAMBLE:
        r = rtcm3(f, b, n, out);
        break;
      default:
        r = text(f, b, n, out);
        break;
    }
    if (r.status != SEMAP_FRAMER_AGAIN) return r;
  }
}
