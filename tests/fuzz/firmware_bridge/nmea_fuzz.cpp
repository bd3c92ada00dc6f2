// NMEA parser: any bytes must give a status, never a crash; an accepted sentence must survive
// encode -> parse with the same type (a heading with its value to two decimals).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "semap/firmware_bridge/nmea.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  SemapNmeaSentence s;
  const SemapFbResult r = semap_nmea_parse(reinterpret_cast<const char*>(data), size, &s);
  if (r.status >= SEMAP_FB_STATUS_COUNT) std::abort();
  if (r.status != SEMAP_FB_OK) return 0;
  char buf[SEMAP_NMEA_MAX_LENGTH + 1];
  std::size_t n = 0;
  switch (s.type) {
    case SEMAP_NMEA_GGA:
      n = semap_nmea_encode_gga(&s.u.gga, s.talker, buf, sizeof buf);
      break;
    case SEMAP_NMEA_RMC:
      n = semap_nmea_encode_rmc(&s.u.rmc, s.talker, buf, sizeof buf);
      break;
    case SEMAP_NMEA_GST:
      n = semap_nmea_encode_gst(&s.u.gst, s.talker, buf, sizeof buf);
      break;
    case SEMAP_NMEA_VTG:
      n = semap_nmea_encode_vtg(&s.u.vtg, s.talker, buf, sizeof buf);
      break;
    case SEMAP_NMEA_HDT:
    case SEMAP_NMEA_THS:
      // A heading the parser accepted lies in [0, 360) and is re-encoded as one.
      if (s.u.heading.has_heading &&
          !(s.u.heading.heading_deg >= 0.0 && s.u.heading.heading_deg < 360.0)) {
        std::abort();
      }
      n = semap_nmea_encode_heading(&s.u.heading, s.type, s.talker, buf, sizeof buf);
      if (n == 0) std::abort();
      break;
  }
  // Re-encoding may not fit in 82 chars (more decimals than the input had): then n == 0.
  if (n > SEMAP_NMEA_STANDARD_LENGTH) std::abort();
  if (n > 0) {
    SemapNmeaSentence again;
    const SemapFbResult r2 = semap_nmea_parse(buf, n, &again);
    if (r2.status == SEMAP_FB_OK && again.type != s.type) std::abort();
    // A heading survives to its two decimals (what rounds to 360.00 wraps to 0).
    if ((s.type == SEMAP_NMEA_HDT || s.type == SEMAP_NMEA_THS) && s.u.heading.has_heading) {
      const double h = s.u.heading.heading_deg;
      const double was = h * 100.0 + 0.5 < 36000.0 ? h : 0.0;
      if (r2.status != SEMAP_FB_OK || !(std::fabs(again.u.heading.heading_deg - was) <= 0.00501)) {
        std::abort();
      }
    }
  }
  return 0;
}
