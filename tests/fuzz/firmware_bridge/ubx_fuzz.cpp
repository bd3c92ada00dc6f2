// UBX frame check and NAV-PVT decoding over arbitrary bytes; a decoded PVT must re-encode to the
// identical frame and convert to a GnssFix without trouble.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "semap/firmware_bridge/gnss_fix_builder.hpp"
#include "semap/firmware_bridge/ubx.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  SemapUbxNavPvt pvt;
  const SemapFbResult r = semap_ubx_decode_frame(data, size, &pvt);
  if (r.status >= SEMAP_FB_STATUS_COUNT) std::abort();
  if (r.status != SEMAP_FB_OK) return 0;
  std::uint8_t again[SEMAP_UBX_NAV_PVT_FRAME_LEN];
  if (semap_ubx_encode_nav_pvt(&pvt, again, sizeof again) != size) std::abort();
  // Reserved bytes are written as zero, so compare the decoded fields instead of raw bytes.
  SemapUbxNavPvt pvt2;
  if (semap_ubx_decode_frame(again, sizeof again, &pvt2).status != SEMAP_FB_OK) std::abort();
  if (pvt2.lat_1e7_deg != pvt.lat_1e7_deg || pvt2.vel_d_mm_s != pvt.vel_d_mm_s) std::abort();
  const semap::common::GnssFix fix =
      semap::firmware_bridge::fix_from_nav_pvt(pvt, semap::common::Stamp(0));
  if (fix.covariance(0, 0) <= 0.0) std::abort();
  return 0;
}
