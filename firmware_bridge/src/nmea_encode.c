/* NMEA encoders for firmware and emulators. Integer formatting only, because printf("%f") is
 * often missing or huge in MCU C libraries. */
#include <string.h>

#include "semap/firmware_bridge/nmea.h"

typedef struct Writer {
  char* buf;
  size_t cap;
  size_t len;
  int overflow;
} Writer;

static void put_char(Writer* w, char c) {
  if (w->len < w->cap) {
    w->buf[w->len++] = c;
  } else {
    w->overflow = 1;
  }
}

static void put_str(Writer* w, const char* s) {
  while (*s) put_char(w, *s++);
}

static void put_uint(Writer* w, uint64_t v, int min_digits) {
  char digits[21];
  int n = 0;
  do {
    digits[n++] = (char)('0' + v % 10u);
    v /= 10u;
  } while (v > 0 && n < 20);
  while (n < min_digits && n < 20) digits[n++] = '0';
  while (n > 0) put_char(w, digits[--n]);
}

/* Fixed-point with `decimals` digits; magnitudes beyond 1e12 are not NMEA values. */
static void put_fixed(Writer* w, double v, int decimals, int min_int_digits) {
  static const uint64_t kScale[] = {1u, 10u, 100u, 1000u, 10000u, 100000u, 1000000u, 10000000u};
  const int negative = v < 0.0;
  double a = negative ? -v : v;
  if (!(a < 1e12)) {
    w->overflow = 1;
    return;
  }
  const uint64_t scaled = (uint64_t)(a * (double)kScale[decimals] + 0.5);
  if (negative && scaled != 0) put_char(w, '-');
  put_uint(w, scaled / kScale[decimals], min_int_digits);
  if (decimals > 0) {
    put_char(w, '.');
    put_uint(w, scaled % kScale[decimals], decimals);
  }
}

static void put_opt_fixed(Writer* w, uint8_t has, double v, int decimals) {
  if (has) put_fixed(w, v, decimals, 1);
  put_char(w, ',');
}

static const char* const kTalkers[SEMAP_NMEA_TALKER_COUNT] = {"GP", "GN", "GL", "GA", "GB",
                                                              "BD", "GQ", "GI", "HE"};

static void begin(Writer* w, SemapNmeaTalker talker, const char* type) {
  if ((unsigned)talker >= SEMAP_NMEA_TALKER_COUNT) {
    w->overflow = 1;
    return;
  }
  put_char(w, '$');
  put_str(w, kTalkers[talker]);
  put_str(w, type);
  put_char(w, ',');
}

static void put_time(Writer* w, uint8_t has, int32_t ms) {
  if (has && ms >= 0) {
    const uint32_t t = (uint32_t)ms;
    put_uint(w, t / 3600000u % 24u, 2);
    put_uint(w, t / 60000u % 60u, 2);
    put_uint(w, t / 1000u % 60u, 2);
    put_char(w, '.');
    put_uint(w, t % 1000u / 10u, 2);
  }
  put_char(w, ',');
}

/* (d)ddmm.mmmmmm: 1e-6 minute is about 2 mm, well inside RTK precision. */
static void put_coordinate(Writer* w, uint8_t has, double deg, int deg_digits, char positive,
                           char negative) {
  const double a = deg < 0.0 ? -deg : deg;
  if (has && !(a <= 180.0)) { /* also NaN: never cast it to an integer */
    w->overflow = 1;
    return;
  }
  if (has) {
    const uint64_t micro_min = (uint64_t)(a * 60e6 + 0.5);
    put_uint(w, micro_min / 60000000u, deg_digits);
    put_uint(w, micro_min % 60000000u / 1000000u, 2);
    put_char(w, '.');
    put_uint(w, micro_min % 1000000u, 6);
    put_char(w, ',');
    put_char(w, deg < 0.0 ? negative : positive);
  } else {
    put_char(w, ',');
  }
  put_char(w, ',');
}

static size_t finish(Writer* w) {
  /* Replace the trailing field separator, then append "*hh\r\n". */
  if (w->len > 0 && w->buf[w->len - 1] == ',') --w->len;
  static const char kHex[] = "0123456789ABCDEF";
  const uint8_t sum = w->overflow || w->len < 1 ? 0 : semap_nmea_checksum(w->buf + 1, w->len - 1);
  put_char(w, '*');
  put_char(w, kHex[sum >> 4]);
  put_char(w, kHex[sum & 0x0Fu]);
  put_char(w, '\r');
  put_char(w, '\n');
  if (w->overflow || w->len > SEMAP_NMEA_STANDARD_LENGTH) return 0;
  if (w->len < w->cap) w->buf[w->len] = '\0';
  return w->len;
}

size_t semap_nmea_encode_gga(const SemapNmeaGga* in, SemapNmeaTalker talker, char* buf,
                             size_t cap) {
  Writer w = {buf, cap, 0, 0};
  begin(&w, talker, "GGA");
  put_time(&w, in->has_time, in->time_ms);
  put_coordinate(&w, in->has_position, in->latitude_deg, 2, 'N', 'S');
  put_coordinate(&w, in->has_position, in->longitude_deg, 3, 'E', 'W');
  put_uint(&w, in->quality, 1);
  put_char(&w, ',');
  put_uint(&w, in->satellites, 2);
  put_char(&w, ',');
  put_opt_fixed(&w, in->has_hdop, in->hdop, 2);
  put_opt_fixed(&w, in->has_altitude, in->altitude_msl_m, 3);
  put_str(&w, in->has_altitude ? "M," : ",");
  put_opt_fixed(&w, in->has_geoid, in->geoid_separation_m, 3);
  put_str(&w, in->has_geoid ? "M," : ",");
  put_opt_fixed(&w, in->has_dgps_age, in->dgps_age_s, 1);
  put_char(&w, ','); /* empty reference station id */
  return finish(&w);
}

size_t semap_nmea_encode_rmc(const SemapNmeaRmc* in, SemapNmeaTalker talker, char* buf,
                             size_t cap) {
  Writer w = {buf, cap, 0, 0};
  begin(&w, talker, "RMC");
  put_time(&w, in->has_time, in->time_ms);
  put_str(&w, in->valid ? "A," : "V,");
  put_coordinate(&w, in->has_position, in->latitude_deg, 2, 'N', 'S');
  put_coordinate(&w, in->has_position, in->longitude_deg, 3, 'E', 'W');
  put_opt_fixed(&w, in->has_speed, in->speed_knots, 3);
  put_opt_fixed(&w, in->has_course, in->course_deg, 2);
  if (in->has_date) {
    put_uint(&w, in->day, 2);
    put_uint(&w, in->month, 2);
    put_uint(&w, in->year % 100u, 2);
  }
  put_str(&w, ",,,"); /* date separator, empty magnetic variation and its direction */
  if (in->mode) put_char(&w, in->mode);
  put_char(&w, ',');
  return finish(&w);
}

size_t semap_nmea_encode_gst(const SemapNmeaGst* in, SemapNmeaTalker talker, char* buf,
                             size_t cap) {
  Writer w = {buf, cap, 0, 0};
  begin(&w, talker, "GST");
  put_time(&w, in->has_time, in->time_ms);
  put_opt_fixed(&w, in->has_rms, in->rms_m, 3);
  put_opt_fixed(&w, in->has_ellipse, in->semi_major_m, 3);
  put_opt_fixed(&w, in->has_ellipse, in->semi_minor_m, 3);
  put_opt_fixed(&w, in->has_ellipse, in->orientation_deg, 1);
  put_opt_fixed(&w, in->has_lat_sd, in->lat_sd_m, 3);
  put_opt_fixed(&w, in->has_lon_sd, in->lon_sd_m, 3);
  put_opt_fixed(&w, in->has_alt_sd, in->alt_sd_m, 3);
  return finish(&w);
}

size_t semap_nmea_encode_vtg(const SemapNmeaVtg* in, SemapNmeaTalker talker, char* buf,
                             size_t cap) {
  Writer w = {buf, cap, 0, 0};
  begin(&w, talker, "VTG");
  put_opt_fixed(&w, in->has_course_true, in->course_true_deg, 2);
  put_str(&w, "T,");
  put_opt_fixed(&w, in->has_course_mag, in->course_mag_deg, 2);
  put_str(&w, "M,");
  put_opt_fixed(&w, in->has_speed_knots, in->speed_knots, 3);
  put_str(&w, "N,");
  put_opt_fixed(&w, in->has_speed_kmh, in->speed_kmh, 3);
  put_str(&w, "K,");
  if (in->mode) put_char(&w, in->mode);
  put_char(&w, ',');
  return finish(&w);
}

size_t semap_nmea_encode_heading(const SemapNmeaHeading* in, SemapNmeaType type,
                                 SemapNmeaTalker talker, char* buf, size_t cap) {
  Writer w = {buf, cap, 0, 0};
  if (type != SEMAP_NMEA_HDT && type != SEMAP_NMEA_THS) return 0;
  begin(&w, talker, type == SEMAP_NMEA_HDT ? "HDT" : "THS");
  /* What would round to 360.00 (put_fixed's rounding) is outside [0, 360): it is 0.00. */
  const double h = in->heading_deg * 100.0 + 0.5 < 36000.0 ? in->heading_deg : 0.0;
  put_opt_fixed(&w, in->has_heading, h, 2);
  if (type == SEMAP_NMEA_HDT) {
    put_str(&w, "T,");
  } else {
    put_char(&w, in->mode ? in->mode : 'V');
    put_char(&w, ',');
  }
  return finish(&w);
}
