/* u-blox UBX framing (sync chars, length, Fletcher-8) and the NAV-PVT message. Plain C99. */
#ifndef SEMAP_FIRMWARE_BRIDGE_UBX_H
#define SEMAP_FIRMWARE_BRIDGE_UBX_H

#include <stddef.h>
#include <stdint.h>

#include "semap/firmware_bridge/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SEMAP_UBX_SYNC1 0xB5u
#define SEMAP_UBX_SYNC2 0x62u
#define SEMAP_UBX_HEADER_LEN 6u    /* sync1 sync2 class id length(2, little-endian) */
#define SEMAP_UBX_OVERHEAD 8u      /* header + CK_A CK_B */
#define SEMAP_UBX_MAX_PAYLOAD 512u /* longer frames are rejected as TOO_LONG */
#define SEMAP_UBX_CLASS_NAV 0x01u
#define SEMAP_UBX_ID_NAV_PVT 0x07u
#define SEMAP_UBX_NAV_PVT_LEN 92u
#define SEMAP_UBX_NAV_PVT_FRAME_LEN (SEMAP_UBX_NAV_PVT_LEN + SEMAP_UBX_OVERHEAD)

/* 8-bit Fletcher over class, id, length and payload (the bytes after the sync chars). */
void semap_ubx_checksum(const uint8_t* data, size_t len, uint8_t* ck_a, uint8_t* ck_b);

/* A checked frame inside a caller's buffer. */
typedef struct SemapUbxFrameView {
  uint8_t msg_class;
  uint8_t msg_id;
  uint16_t length;
  const uint8_t* payload;
} SemapUbxFrameView;

/* Checks sync chars, length against `len` and the checksum. TRUNCATED when `len` is shorter
 * than the frame, TOO_LONG when it is longer or over SEMAP_UBX_MAX_PAYLOAD, BAD_FIELD (0/1)
 * for wrong sync chars, BAD_CHECKSUM on mismatch. */
SemapFbResult semap_ubx_check_frame(const uint8_t* frame, size_t len, SemapUbxFrameView* out);

/* Bits of SemapUbxNavPvt.flags. */
#define SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK 0x01u
#define SEMAP_UBX_PVT_FLAG_DIFF_SOLN 0x02u
#define SEMAP_UBX_PVT_CARR_SOLN_SHIFT 6u /* 0 none, 1 float, 2 fixed */
#define SEMAP_UBX_PVT_VALID_DATE 0x01u
#define SEMAP_UBX_PVT_VALID_TIME 0x02u

/* UBX-NAV-PVT in its wire units (see the u-blox interface description). */
typedef struct SemapUbxNavPvt {
  uint32_t itow_ms;
  uint16_t year;
  uint8_t month, day, hour, min, sec;
  uint8_t valid;
  uint32_t t_acc_ns;
  int32_t nano_ns;
  uint8_t fix_type; /* 0 none, 1 dead reckoning, 2 2D, 3 3D, 4 GNSS+DR, 5 time only */
  uint8_t flags;
  uint8_t flags2;
  uint8_t num_sv;
  int32_t lon_1e7_deg, lat_1e7_deg;
  int32_t height_mm; /* above ellipsoid */
  int32_t h_msl_mm;
  uint32_t h_acc_mm, v_acc_mm;
  int32_t vel_n_mm_s, vel_e_mm_s, vel_d_mm_s;
  int32_t g_speed_mm_s;
  int32_t head_mot_1e5_deg;
  uint32_t s_acc_mm_s;
  uint32_t head_acc_1e5_deg;
  uint16_t p_dop_001;
  uint8_t flags3;
  int32_t head_veh_1e5_deg;
  int16_t mag_dec_1e2_deg;
  uint16_t mag_acc_1e2_deg;
} SemapUbxNavPvt;

/* Decodes a 92-byte NAV-PVT payload. TRUNCATED / TOO_LONG for another length, BAD_FIELD with
 * the payload byte offset of an out-of-range value (month, day, fix type, lat, lon). */
SemapFbResult semap_ubx_decode_nav_pvt(const uint8_t* payload, size_t len, SemapUbxNavPvt* out);

/* Checks a whole frame and decodes it: UNKNOWN for a valid frame of another class/id. */
SemapFbResult semap_ubx_decode_frame(const uint8_t* frame, size_t len, SemapUbxNavPvt* out);

/* Writes a complete NAV-PVT frame (SEMAP_UBX_NAV_PVT_FRAME_LEN bytes); returns its length or 0
 * when `cap` is too small. */
size_t semap_ubx_encode_nav_pvt(const SemapUbxNavPvt* in, uint8_t* buf, size_t cap);

#ifdef __cplusplus
}
#endif

#endif /* SEMAP_FIRMWARE_BRIDGE_UBX_H */
