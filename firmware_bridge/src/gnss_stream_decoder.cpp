#include "semap/firmware_bridge/gnss_stream_decoder.hpp"

#include "semap/firmware_bridge/nmea.h"
#include "semap/firmware_bridge/ubx.h"

namespace semap::firmware_bridge {

GnssStreamCounters& GnssStreamCounters::operator+=(const GnssStreamCounters& o) {
  bytes += o.bytes;
  garbage_bytes += o.garbage_bytes;
  nmea_sentences += o.nmea_sentences;
  ubx_frames += o.ubx_frames;
  rtcm3_frames += o.rtcm3_frames;
  text_lines += o.text_lines;
  bad_checksum += o.bad_checksum;
  too_long += o.too_long;
  truncated += o.truncated;
  unknown += o.unknown;
  bad_field += o.bad_field;
  fixes += o.fixes;
  return *this;
}

GnssStreamDecoder::GnssStreamDecoder(const GnssFixBuilderConfig& config) : builder_(config) {
  semap_gnss_framer_init(&framer_);
}

void GnssStreamDecoder::feed(std::span<const std::uint8_t> bytes, common::Stamp stamp,
                             std::vector<common::GnssFix>& fixes) {
  while (!bytes.empty()) {
    const std::size_t taken = semap_gnss_framer_push(&framer_, bytes.data(), bytes.size());
    bytes = bytes.subspan(taken);
    drain(stamp, fixes);
  }
  counters_.bytes = framer_.counters.bytes;
  counters_.garbage_bytes = framer_.counters.garbage_bytes;
}

void GnssStreamDecoder::count(SemapFbStatus status) {
  switch (status) {
    case SEMAP_FB_BAD_CHECKSUM:
      ++counters_.bad_checksum;
      break;
    case SEMAP_FB_TOO_LONG:
      ++counters_.too_long;
      break;
    case SEMAP_FB_TRUNCATED:
      ++counters_.truncated;
      break;
    case SEMAP_FB_UNKNOWN:
      ++counters_.unknown;
      break;
    case SEMAP_FB_BAD_FIELD:
      ++counters_.bad_field;
      break;
    default:
      break;
  }
}

void GnssStreamDecoder::drain(common::Stamp stamp, std::vector<common::GnssFix>& fixes) {
  for (;;) {
    SemapGnssFrame frame;
    const SemapFbResult r = semap_gnss_framer_next(&framer_, &frame);
    if (r.status == SEMAP_FB_NEED_MORE) return;
    if (r.status != SEMAP_FB_OK) {
      count(r.status);
      continue;
    }
    if (frame.kind == SEMAP_GNSS_FRAME_RTCM3) {
      ++counters_.rtcm3_frames;
    } else if (frame.kind == SEMAP_GNSS_FRAME_TEXT) {
      ++counters_.text_lines;
    } else if (frame.kind == SEMAP_GNSS_FRAME_UBX_SKIPPED) {
      ++counters_.unknown;  // no decoded message is that long
    } else if (frame.kind == SEMAP_GNSS_FRAME_NMEA) {
      SemapNmeaSentence sentence;
      const SemapFbResult p =
          semap_nmea_parse(reinterpret_cast<const char*>(frame.data), frame.len, &sentence);
      if (p.status != SEMAP_FB_OK) {
        count(p.status);
        continue;
      }
      ++counters_.nmea_sentences;
      if (auto fix = builder_.add(sentence, stamp)) {
        fixes.push_back(*fix);
        ++counters_.fixes;
      }
    } else {
      SemapUbxNavPvt pvt;
      const SemapFbResult p = semap_ubx_decode_frame(frame.data, frame.len, &pvt);
      if (p.status != SEMAP_FB_OK) {
        count(p.status);
        continue;
      }
      ++counters_.ubx_frames;
      fixes.push_back(fix_from_nav_pvt(pvt, stamp));
      ++counters_.fixes;
    }
  }
}

}  // namespace semap::firmware_bridge
