/* Locale-free number parsing for NMEA fields (private to firmware_bridge). */
#ifndef SEMAP_FIRMWARE_BRIDGE_SRC_NMEA_TEXT_H
#define SEMAP_FIRMWARE_BRIDGE_SRC_NMEA_TEXT_H

#include <stddef.h>
#include <stdint.h>

/* Powers of ten that are exact doubles, so one division rounds correctly. */
static const double kSemapPow10[19] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8, 1e9,
                                       1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18};

/* [+-]digits[.digits] with at least one and at most 18 digits; returns 0 when malformed. */
static inline int semap_nmea_parse_decimal(const char* s, size_t n, double* out) {
  size_t i = 0;
  int negative = 0;
  if (n > 0 && (s[0] == '-' || s[0] == '+')) {
    negative = s[0] == '-';
    i = 1;
  }
  uint64_t mantissa = 0;
  int digits = 0;
  int decimals = 0;
  int seen_dot = 0;
  for (; i < n; ++i) {
    const char c = s[i];
    if (c == '.') {
      if (seen_dot) return 0;
      seen_dot = 1;
      continue;
    }
    if (c < '0' || c > '9') return 0;
    if (++digits > 18) return 0;
    mantissa = mantissa * 10u + (uint64_t)(c - '0');
    decimals += seen_dot;
  }
  if (digits == 0) return 0;
  const double v = (double)mantissa / kSemapPow10[decimals];
  *out = negative ? -v : v;
  return 1;
}

/* 1..9 digits, value <= max. */
static inline int semap_nmea_parse_uint(const char* s, size_t n, uint32_t max, uint32_t* out) {
  if (n == 0 || n > 9) return 0;
  uint32_t v = 0;
  for (size_t i = 0; i < n; ++i) {
    if (s[i] < '0' || s[i] > '9') return 0;
    v = v * 10u + (uint32_t)(s[i] - '0');
  }
  if (v > max) return 0;
  *out = v;
  return 1;
}

#endif /* SEMAP_FIRMWARE_BRIDGE_SRC_NMEA_TEXT_H */
