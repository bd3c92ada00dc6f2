/* NMEA 0183 GGA, RMC, GST, VTG, HDT and THS: parser with checksum and length checks, and encoders.
 * Plain C99, no allocation, no locale-dependent number parsing. */
#ifndef SEMAP_FIRMWARE_BRIDGE_NMEA_H
#define SEMAP_FIRMWARE_BRIDGE_NMEA_H

#include <stddef.h>
#include <stdint.h>

#include "semap/firmware_bridge/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* NMEA 0183's limit, '$' through CR LF inclusive: what the encoders write. */
#define SEMAP_NMEA_STANDARD_LENGTH 82u
/* What the parser and the framer accept, '$' through CR LF inclusive. Real receivers exceed 82:
 * high-precision ones print 7-8 decimals of minutes (GGA of 89-101 bytes) and NMEA 4.x lets
 * proprietary sentences run longer. 255 covers both with room to spare and still bounds how
 * long a line that lost its LF is buffered. */
#define SEMAP_NMEA_MAX_LENGTH 255u

typedef enum SemapNmeaTalker {
  SEMAP_NMEA_TALKER_GP = 0, /* GPS */
  SEMAP_NMEA_TALKER_GN,     /* multi-constellation */
  SEMAP_NMEA_TALKER_GL,     /* GLONASS */
  SEMAP_NMEA_TALKER_GA,     /* Galileo */
  SEMAP_NMEA_TALKER_GB,     /* BeiDou (NMEA 4.10) */
  SEMAP_NMEA_TALKER_BD,     /* BeiDou (older receivers, e.g. ST Teseo) */
  SEMAP_NMEA_TALKER_GQ,     /* QZSS */
  SEMAP_NMEA_TALKER_GI,     /* NavIC (IRNSS) */
  SEMAP_NMEA_TALKER_HE,     /* heading sensor: dual-antenna receivers' HDT (e.g. Hemisphere) */
  SEMAP_NMEA_TALKER_COUNT
} SemapNmeaTalker;

typedef enum SemapNmeaType {
  SEMAP_NMEA_GGA = 0,
  SEMAP_NMEA_RMC,
  SEMAP_NMEA_GST,
  SEMAP_NMEA_VTG,
  SEMAP_NMEA_HDT,
  SEMAP_NMEA_THS
} SemapNmeaType;

/* Empty fields are legal in NMEA; each optional value has a has_ flag. Time of day is UTC in
 * milliseconds since midnight. Latitude/longitude are signed degrees (south/west negative). */
typedef struct SemapNmeaGga {
  uint8_t has_time, has_position, has_hdop, has_altitude, has_geoid, has_dgps_age;
  int32_t time_ms;
  double latitude_deg, longitude_deg;
  uint8_t quality; /* 0 invalid, 1 GPS, 2 DGPS, 3 PPS, 4 RTK fixed, 5 RTK float, 6 DR, ... */
  uint8_t satellites;
  double hdop;
  double altitude_msl_m;
  double geoid_separation_m; /* ellipsoid height = altitude_msl_m + geoid_separation_m */
  double dgps_age_s;
} SemapNmeaGga;

typedef struct SemapNmeaRmc {
  uint8_t has_time, has_position, has_speed, has_course, has_date;
  int32_t time_ms;
  uint8_t valid; /* status 'A' */
  double latitude_deg, longitude_deg;
  double speed_knots;
  double course_deg; /* over ground, true */
  uint8_t day, month;
  uint16_t year; /* four digits (two-digit years map to 1980..2079) */
  char mode;     /* FAA mode indicator (A, D, E, F, N, R...) or 0 when absent */
} SemapNmeaRmc;

typedef struct SemapNmeaGst {
  uint8_t has_time, has_rms, has_ellipse, has_lat_sd, has_lon_sd, has_alt_sd;
  int32_t time_ms;
  double rms_m;
  double semi_major_m, semi_minor_m, orientation_deg; /* 1-sigma ellipse, deg from true north */
  double lat_sd_m, lon_sd_m, alt_sd_m;
} SemapNmeaGst;

typedef struct SemapNmeaVtg {
  uint8_t has_course_true, has_course_mag, has_speed_knots, has_speed_kmh;
  double course_true_deg, course_mag_deg;
  double speed_knots, speed_kmh;
  char mode;
} SemapNmeaVtg;

/* True heading of a dual-antenna (moving-base) receiver's baseline, or of a gyrocompass:
 * HDT "$xxHDT,hhh.hh,T" and THS "$xxTHS,hhh.hh,m". Degrees clockwise from true north in
 * [0, 360). HDT has no status: an empty heading means none. THS's mode: 'A' autonomous,
 * 'E' estimated (dead reckoning), 'M' manual, 'S' simulator, 'V' not valid; HDT reads as 'A'
 * when it has a heading. Neither carries a time: a receiver sends them in its epoch. */
typedef struct SemapNmeaHeading {
  uint8_t has_heading;
  double heading_deg;
  char mode;
} SemapNmeaHeading;

typedef struct SemapNmeaSentence {
  SemapNmeaTalker talker;
  SemapNmeaType type;
  union {
    SemapNmeaGga gga;
    SemapNmeaRmc rmc;
    SemapNmeaGst gst;
    SemapNmeaVtg vtg;
    SemapNmeaHeading heading; /* HDT and THS */
  } u;
} SemapNmeaSentence;

/* Parses one sentence "$ttSSS,...*hh" with optional trailing CR LF. Returns TOO_LONG over
 * SEMAP_NMEA_MAX_LENGTH chars, TRUNCATED without '$' or "*hh", BAD_CHECKSUM on mismatch, UNKNOWN
 * for another talker or sentence, BAD_FIELD with the 0-based field index (after the address) of a
 * bad value. */
SemapFbResult semap_nmea_parse(const char* text, size_t len, SemapNmeaSentence* out);

/* XOR of the characters between '$' and '*' (exclusive). */
uint8_t semap_nmea_checksum(const char* body, size_t len);

/* Encoders: write "$..*hh\r\n" into buf and return its length (no terminating NUL counted),
 * or 0 when it does not fit in `cap` or SEMAP_NMEA_STANDARD_LENGTH. Fields with has_ == 0 are left
 * empty. A NUL is appended when room remains. */
size_t semap_nmea_encode_gga(const SemapNmeaGga* in, SemapNmeaTalker talker, char* buf, size_t cap);
size_t semap_nmea_encode_rmc(const SemapNmeaRmc* in, SemapNmeaTalker talker, char* buf, size_t cap);
size_t semap_nmea_encode_gst(const SemapNmeaGst* in, SemapNmeaTalker talker, char* buf, size_t cap);
size_t semap_nmea_encode_vtg(const SemapNmeaVtg* in, SemapNmeaTalker talker, char* buf, size_t cap);
/* HDT (the mode is not written) or THS (mode 'V' when in->mode is 0), by `type`. */
size_t semap_nmea_encode_heading(const SemapNmeaHeading* in, SemapNmeaType type,
                                 SemapNmeaTalker talker, char* buf, size_t cap);

#ifdef __cplusplus
}
#endif

#endif /* SEMAP_FIRMWARE_BRIDGE_NMEA_H */
