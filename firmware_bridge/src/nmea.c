#include "semap/firmware_bridge/nmea.h"

#include <string.h>

#include "nmea_text.h"

#define SEMAP_NMEA_MAX_FIELDS 24

typedef struct Field {
  const char* s;
  size_t n;
} Field;

static SemapFbResult result(SemapFbStatus status, int16_t field) {
  SemapFbResult r;
  r.status = status;
  r.field = field;
  return r;
}

static SemapFbResult bad(int index) { return result(SEMAP_FB_BAD_FIELD, (int16_t)index); }

uint8_t semap_nmea_checksum(const char* body, size_t len) {
  uint8_t sum = 0;
  for (size_t i = 0; i < len; ++i) sum ^= (uint8_t)body[i];
  return sum;
}

static int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

/* Optional decimal; returns 0 when malformed. An empty field leaves *has at 0. */
static int opt_decimal(Field f, uint8_t* has, double* out) {
  *has = 0;
  if (f.n == 0) return 1;
  if (!semap_nmea_parse_decimal(f.s, f.n, out)) return 0;
  *has = 1;
  return 1;
}

/* hhmmss[.sss] into milliseconds of the day. */
static int parse_time(Field f, uint8_t* has, int32_t* ms) {
  *has = 0;
  if (f.n == 0) return 1;
  if (f.n < 6) return 0;
  uint32_t hh, mm, ss;
  if (!semap_nmea_parse_uint(f.s, 2, 23, &hh) || !semap_nmea_parse_uint(f.s + 2, 2, 59, &mm) ||
      !semap_nmea_parse_uint(f.s + 4, 2, 60, &ss)) {
    return 0;
  }
  double frac = 0.0;
  if (f.n > 6) {
    if (f.s[6] != '.') return 0;
    if (f.n > 7 && !semap_nmea_parse_decimal(f.s + 6, f.n - 6, &frac)) return 0;
  }
  *ms = (int32_t)(((hh * 60u + mm) * 60u + ss) * 1000u) + (int32_t)(frac * 1000.0 + 0.5);
  *has = 1;
  return 1;
}

/* (d)ddmm.mmmm plus hemisphere into signed degrees; both empty means "no position". */
static int parse_coordinate(Field value, Field hemi, double max_deg, char positive, char negative,
                            uint8_t* has, double* deg) {
  *has = 0;
  if (value.n == 0 && hemi.n == 0) return 1;
  double v;
  if (value.n == 0 || hemi.n != 1 || !semap_nmea_parse_decimal(value.s, value.n, &v) || v < 0.0) {
    return 0;
  }
  /* Bound before the integer cast: long may be 32 bits on an MCU. */
  if (v >= 100.0 * (max_deg + 1.0)) return 0;
  const double whole = (double)(long)(v / 100.0);
  const double minutes = v - whole * 100.0;
  if (minutes >= 60.0) return 0;
  double d = whole + minutes / 60.0;
  if (d > max_deg) return 0;
  if (hemi.s[0] == negative) {
    d = -d;
  } else if (hemi.s[0] != positive) {
    return -1; /* hemisphere field is the bad one */
  }
  *deg = d;
  *has = 1;
  return 1;
}

static int unit_is(Field f, char unit) { return f.n == 0 || (f.n == 1 && f.s[0] == unit); }

static SemapFbResult parse_gga(const Field* f, int n, SemapNmeaGga* g) {
  if (n < 14) return bad(n);
  memset(g, 0, sizeof *g);
  if (!parse_time(f[0], &g->has_time, &g->time_ms)) return bad(0);
  int c = parse_coordinate(f[1], f[2], 90.0, 'N', 'S', &g->has_position, &g->latitude_deg);
  if (c <= 0) return bad(c < 0 ? 2 : 1);
  uint8_t has_lon = 0;
  c = parse_coordinate(f[3], f[4], 180.0, 'E', 'W', &has_lon, &g->longitude_deg);
  if (c <= 0) return bad(c < 0 ? 4 : 3);
  if (has_lon != g->has_position) return bad(has_lon ? 1 : 3);
  uint32_t v;
  if (!semap_nmea_parse_uint(f[5].s, f[5].n, 9, &v)) return bad(5);
  g->quality = (uint8_t)v;
  if (f[6].n > 0) {
    if (!semap_nmea_parse_uint(f[6].s, f[6].n, 99, &v)) return bad(6);
    g->satellites = (uint8_t)v;
  }
  if (!opt_decimal(f[7], &g->has_hdop, &g->hdop) || (g->has_hdop && g->hdop < 0.0)) return bad(7);
  if (!opt_decimal(f[8], &g->has_altitude, &g->altitude_msl_m)) return bad(8);
  if (!unit_is(f[9], 'M')) return bad(9);
  if (!opt_decimal(f[10], &g->has_geoid, &g->geoid_separation_m)) return bad(10);
  if (!unit_is(f[11], 'M')) return bad(11);
  if (!opt_decimal(f[12], &g->has_dgps_age, &g->dgps_age_s)) return bad(12);
  return result(SEMAP_FB_OK, -1);
}

static int parse_mode(Field f, char* mode) {
  *mode = 0;
  if (f.n == 0) return 1;
  if (f.n != 1 || f.s[0] < 'A' || f.s[0] > 'Z') return 0;
  *mode = f.s[0];
  return 1;
}

static SemapFbResult parse_rmc(const Field* f, int n, SemapNmeaRmc* r) {
  if (n < 11) return bad(n);
  memset(r, 0, sizeof *r);
  if (!parse_time(f[0], &r->has_time, &r->time_ms)) return bad(0);
  if (f[1].n != 1 || (f[1].s[0] != 'A' && f[1].s[0] != 'V')) return bad(1);
  r->valid = f[1].s[0] == 'A';
  int c = parse_coordinate(f[2], f[3], 90.0, 'N', 'S', &r->has_position, &r->latitude_deg);
  if (c <= 0) return bad(c < 0 ? 3 : 2);
  uint8_t has_lon = 0;
  c = parse_coordinate(f[4], f[5], 180.0, 'E', 'W', &has_lon, &r->longitude_deg);
  if (c <= 0) return bad(c < 0 ? 5 : 4);
  if (has_lon != r->has_position) return bad(has_lon ? 2 : 4);
  if (!opt_decimal(f[6], &r->has_speed, &r->speed_knots) || r->speed_knots < 0.0) return bad(6);
  if (!opt_decimal(f[7], &r->has_course, &r->course_deg)) return bad(7);
  if (f[8].n > 0) {
    uint32_t d, m, y;
    if (f[8].n != 6 || !semap_nmea_parse_uint(f[8].s, 2, 31, &d) ||
        !semap_nmea_parse_uint(f[8].s + 2, 2, 12, &m) ||
        !semap_nmea_parse_uint(f[8].s + 4, 2, 99, &y) || d == 0 || m == 0) {
      return bad(8);
    }
    r->day = (uint8_t)d;
    r->month = (uint8_t)m;
    r->year = (uint16_t)(y < 80 ? 2000 + y : 1900 + y);
    r->has_date = 1;
  }
  if (n > 11 && !parse_mode(f[11], &r->mode)) return bad(11);
  return result(SEMAP_FB_OK, -1);
}

static SemapFbResult parse_gst(const Field* f, int n, SemapNmeaGst* g) {
  if (n < 8) return bad(n);
  memset(g, 0, sizeof *g);
  if (!parse_time(f[0], &g->has_time, &g->time_ms)) return bad(0);
  if (!opt_decimal(f[1], &g->has_rms, &g->rms_m)) return bad(1);
  uint8_t has[3];
  double* ellipse[3] = {&g->semi_major_m, &g->semi_minor_m, &g->orientation_deg};
  for (int i = 0; i < 3; ++i) {
    if (!opt_decimal(f[2 + i], &has[i], ellipse[i])) return bad(2 + i);
  }
  g->has_ellipse = has[0] && has[1] && has[2];
  if (!opt_decimal(f[5], &g->has_lat_sd, &g->lat_sd_m) || g->lat_sd_m < 0.0) return bad(5);
  if (!opt_decimal(f[6], &g->has_lon_sd, &g->lon_sd_m) || g->lon_sd_m < 0.0) return bad(6);
  if (!opt_decimal(f[7], &g->has_alt_sd, &g->alt_sd_m) || g->alt_sd_m < 0.0) return bad(7);
  if (g->semi_major_m < 0.0 || g->semi_minor_m < 0.0) return bad(2);
  return result(SEMAP_FB_OK, -1);
}

static SemapFbResult parse_vtg(const Field* f, int n, SemapNmeaVtg* v) {
  if (n < 8) return bad(n);
  memset(v, 0, sizeof *v);
  if (!opt_decimal(f[0], &v->has_course_true, &v->course_true_deg)) return bad(0);
  if (!unit_is(f[1], 'T')) return bad(1);
  if (!opt_decimal(f[2], &v->has_course_mag, &v->course_mag_deg)) return bad(2);
  if (!unit_is(f[3], 'M')) return bad(3);
  if (!opt_decimal(f[4], &v->has_speed_knots, &v->speed_knots) || v->speed_knots < 0.0)
    return bad(4);
  if (!unit_is(f[5], 'N')) return bad(5);
  if (!opt_decimal(f[6], &v->has_speed_kmh, &v->speed_kmh) || v->speed_kmh < 0.0) return bad(6);
  if (!unit_is(f[7], 'K')) return bad(7);
  if (n > 8 && !parse_mode(f[8], &v->mode)) return bad(8);
  return result(SEMAP_FB_OK, -1);
}

/* HDT: heading, 'T'. THS: heading, mode. A heading outside [0, 360) is a bad field. */
static SemapFbResult parse_heading(const Field* f, int n, SemapNmeaType type, SemapNmeaHeading* h) {
  if (n < 2) return bad(n);
  memset(h, 0, sizeof *h);
  if (!opt_decimal(f[0], &h->has_heading, &h->heading_deg) ||
      (h->has_heading && !(h->heading_deg >= 0.0 && h->heading_deg < 360.0))) {
    return bad(0);
  }
  if (type == SEMAP_NMEA_HDT) {
    if (f[1].n != 1 || f[1].s[0] != 'T') return bad(1);
    h->mode = h->has_heading ? 'A' : 'V';
    return result(SEMAP_FB_OK, -1);
  }
  static const char kModes[] = "AEMSV";
  if (f[1].n != 1 || !memchr(kModes, f[1].s[0], sizeof kModes - 1)) return bad(1);
  h->mode = f[1].s[0];
  return result(SEMAP_FB_OK, -1);
}

static int parse_talker(const char* s, SemapNmeaTalker* talker) {
  static const char* const kTalkers[SEMAP_NMEA_TALKER_COUNT] = {"GP", "GN", "GL", "GA", "GB",
                                                                "BD", "GQ", "GI", "HE"};
  for (int i = 0; i < (int)SEMAP_NMEA_TALKER_COUNT; ++i) {
    if (s[0] == kTalkers[i][0] && s[1] == kTalkers[i][1]) {
      *talker = (SemapNmeaTalker)i;
      return 1;
    }
  }
  return 0;
}

static int parse_type(const char* s, SemapNmeaType* type) {
  static const char* const kTypes[] = {"GGA", "RMC", "GST", "VTG", "HDT", "THS"};
  for (int i = 0; i < 6; ++i) {
    if (memcmp(s, kTypes[i], 3) == 0) {
      *type = (SemapNmeaType)i;
      return 1;
    }
  }
  return 0;
}

SemapFbResult semap_nmea_parse(const char* text, size_t len, SemapNmeaSentence* out) {
  if (len > SEMAP_NMEA_MAX_LENGTH) return result(SEMAP_FB_TOO_LONG, -1);
  size_t n = len;
  int terminated = 0;
  while (n > 0 && (text[n - 1] == '\n' || text[n - 1] == '\r')) {
    --n;
    terminated = 1;
  }
  /* Without CR LF the sentence itself may use at most all but two of the characters. */
  if (!terminated && n > SEMAP_NMEA_MAX_LENGTH - 2) return result(SEMAP_FB_TOO_LONG, -1);
  if (n < 4 || text[0] != '$' || text[n - 3] != '*') return result(SEMAP_FB_TRUNCATED, -1);
  const int hi = hex_value(text[n - 2]);
  const int lo = hex_value(text[n - 1]);
  const char* body = text + 1;
  const size_t body_len = n - 4;
  if (hi < 0 || lo < 0 || semap_nmea_checksum(body, body_len) != (uint8_t)(hi * 16 + lo)) {
    return result(SEMAP_FB_BAD_CHECKSUM, -1);
  }
  if (body_len < 5 || (body_len > 5 && body[5] != ',')) return result(SEMAP_FB_UNKNOWN, -1);
  if (!parse_talker(body, &out->talker) || !parse_type(body + 2, &out->type)) {
    return result(SEMAP_FB_UNKNOWN, -1);
  }
  Field fields[SEMAP_NMEA_MAX_FIELDS];
  int count = 0;
  if (body_len > 5) {
    const char* p = body + 6;
    const char* end = body + body_len;
    for (;;) {
      if (count == SEMAP_NMEA_MAX_FIELDS) return bad(count);
      const char* comma = memchr(p, ',', (size_t)(end - p));
      const char* stop = comma ? comma : end;
      fields[count].s = p;
      fields[count].n = (size_t)(stop - p);
      ++count;
      if (!comma) break;
      p = comma + 1;
    }
  }
  switch (out->type) {
    case SEMAP_NMEA_GGA:
      return parse_gga(fields, count, &out->u.gga);
    case SEMAP_NMEA_RMC:
      return parse_rmc(fields, count, &out->u.rmc);
    case SEMAP_NMEA_GST:
      return parse_gst(fields, count, &out->u.gst);
    case SEMAP_NMEA_VTG:
      return parse_vtg(fields, count, &out->u.vtg);
    case SEMAP_NMEA_HDT:
    case SEMAP_NMEA_THS:
      return parse_heading(fields, count, out->type, &out->u.heading);
  }
  return result(SEMAP_FB_UNKNOWN, -1);
}
