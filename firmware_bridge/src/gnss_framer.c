#include "semap/firmware_bridge/gnss_framer.h"

#include <string.h>

#include "bytes.h"
#include "semap/firmware_bridge/nmea.h"
#include "semap/firmware_bridge/ubx.h"

#define SEMAP_NMEA_ADDRESS_END 6u /* '$' + 5 address chars */

static SemapFbResult result(SemapFbStatus status) {
  SemapFbResult r;
  r.status = status;
  r.field = -1;
  return r;
}

void semap_gnss_framer_init(SemapGnssFramer* f) { memset(f, 0, sizeof *f); }

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
  f->begin += n;
  if (garbage) f->counters.garbage_bytes += n;
}

SemapFbResult semap_gnss_framer_next(SemapGnssFramer* f, SemapGnssFrame* out) {
  for (;;) {
    const uint8_t* b = f->buf + f->begin;
    size_t n = f->end - f->begin;
    size_t i = 0;
    while (i < n && b[i] != '$' && b[i] != SEMAP_UBX_SYNC1) ++i;
    skip(f, i, 1);
    b += i;
    n -= i;
    if (n == 0) return result(SEMAP_FB_NEED_MORE);

    if (b[0] == '$') {
      size_t k = 1;
      while (k < n && k < SEMAP_NMEA_ADDRESS_END && address_char(b[k], k)) ++k;
      if (k < SEMAP_NMEA_ADDRESS_END) {
        if (k == n) return result(SEMAP_FB_NEED_MORE);
        skip(f, 1, 1);
        continue;
      }
      const size_t limit = n < SEMAP_NMEA_MAX_LENGTH ? n : SEMAP_NMEA_MAX_LENGTH;
      for (; k < limit; ++k) {
        const uint8_t c = b[k];
        if (c == '\n') {
          out->kind = SEMAP_GNSS_FRAME_NMEA;
          out->data = b;
          out->len = k + 1;
          skip(f, k + 1, 0);
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

    if (n < 2) return result(SEMAP_FB_NEED_MORE);
    if (b[1] != SEMAP_UBX_SYNC2) {
      skip(f, 1, 1);
      continue;
    }
    if (n < SEMAP_UBX_HEADER_LEN) return result(SEMAP_FB_NEED_MORE);
    const size_t length = semap_get_u16(b + 4);
    if (length > SEMAP_UBX_MAX_PAYLOAD) {
      skip(f, 2, 0);
      f->counters.too_long++;
      return result(SEMAP_FB_TOO_LONG);
    }
    const size_t total = length + SEMAP_UBX_OVERHEAD;
    if (n < total) return result(SEMAP_FB_NEED_MORE);
    uint8_t a, c;
    semap_ubx_checksum(b + 2, length + 4u, &a, &c);
    if (a != b[total - 2] || c != b[total - 1]) {
      /* Skip only the sync chars: a frame cut short hides the start of the next one. */
      skip(f, 2, 0);
      f->counters.bad_checksum++;
      return result(SEMAP_FB_BAD_CHECKSUM);
    }
    out->kind = SEMAP_GNSS_FRAME_UBX;
    out->data = b;
    out->len = total;
    skip(f, total, 0);
    f->counters.ubx_frames++;
    return result(SEMAP_FB_OK);
  }
}
