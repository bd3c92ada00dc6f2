#include "semap/firmware_bridge/ubx.h"

#include <string.h>

#include "bytes.h"

static SemapFbResult result(SemapFbStatus status, int16_t field) {
  SemapFbResult r;
  r.status = status;
  r.field = field;
  return r;
}

void semap_ubx_checksum(const uint8_t* data, size_t len, uint8_t* ck_a, uint8_t* ck_b) {
  uint8_t a = 0;
  uint8_t b = 0;
  for (size_t i = 0; i < len; ++i) {
    a = (uint8_t)(a + data[i]);
    b = (uint8_t)(b + a);
  }
  *ck_a = a;
  *ck_b = b;
}

SemapFbResult semap_ubx_check_frame(const uint8_t* frame, size_t len, SemapUbxFrameView* out) {
  if (len < SEMAP_UBX_OVERHEAD) return result(SEMAP_FB_TRUNCATED, -1);
  if (frame[0] != SEMAP_UBX_SYNC1) return result(SEMAP_FB_BAD_FIELD, 0);
  if (frame[1] != SEMAP_UBX_SYNC2) return result(SEMAP_FB_BAD_FIELD, 1);
  const uint16_t length = semap_get_u16(frame + 4);
  if (length > SEMAP_UBX_MAX_PAYLOAD) return result(SEMAP_FB_TOO_LONG, 4);
  const size_t total = (size_t)length + SEMAP_UBX_OVERHEAD;
  if (len < total) return result(SEMAP_FB_TRUNCATED, -1);
  if (len > total) return result(SEMAP_FB_TOO_LONG, -1);
  uint8_t a, b;
  semap_ubx_checksum(frame + 2, (size_t)length + 4u, &a, &b);
  if (a != frame[total - 2] || b != frame[total - 1]) return result(SEMAP_FB_BAD_CHECKSUM, -1);
  out->msg_class = frame[2];
  out->msg_id = frame[3];
  out->length = length;
  out->payload = frame + SEMAP_UBX_HEADER_LEN;
  return result(SEMAP_FB_OK, -1);
}

SemapFbResult semap_ubx_decode_nav_pvt(const uint8_t* p, size_t len, SemapUbxNavPvt* out) {
  if (len < SEMAP_UBX_NAV_PVT_LEN) return result(SEMAP_FB_TRUNCATED, -1);
  if (len > SEMAP_UBX_NAV_PVT_LEN) return result(SEMAP_FB_TOO_LONG, -1);
  memset(out, 0, sizeof *out);
  out->itow_ms = semap_get_u32(p + 0);
  out->year = semap_get_u16(p + 4);
  out->month = p[6];
  out->day = p[7];
  out->hour = p[8];
  out->min = p[9];
  out->sec = p[10];
  out->valid = p[11];
  out->t_acc_ns = semap_get_u32(p + 12);
  out->nano_ns = semap_get_i32(p + 16);
  out->fix_type = p[20];
  out->flags = p[21];
  out->flags2 = p[22];
  out->num_sv = p[23];
  out->lon_1e7_deg = semap_get_i32(p + 24);
  out->lat_1e7_deg = semap_get_i32(p + 28);
  out->height_mm = semap_get_i32(p + 32);
  out->h_msl_mm = semap_get_i32(p + 36);
  out->h_acc_mm = semap_get_u32(p + 40);
  out->v_acc_mm = semap_get_u32(p + 44);
  out->vel_n_mm_s = semap_get_i32(p + 48);
  out->vel_e_mm_s = semap_get_i32(p + 52);
  out->vel_d_mm_s = semap_get_i32(p + 56);
  out->g_speed_mm_s = semap_get_i32(p + 60);
  out->head_mot_1e5_deg = semap_get_i32(p + 64);
  out->s_acc_mm_s = semap_get_u32(p + 68);
  out->head_acc_1e5_deg = semap_get_u32(p + 72);
  out->p_dop_001 = semap_get_u16(p + 76);
  out->flags3 = p[78];
  out->head_veh_1e5_deg = semap_get_i32(p + 84);
  out->mag_dec_1e2_deg = semap_get_i16(p + 88);
  out->mag_acc_1e2_deg = semap_get_u16(p + 90);
  /* Ranges from the u-blox interface description; anything else means corrupt data that
   * slipped through the checksum or a receiver bug. */
  if (out->month > 12) return result(SEMAP_FB_BAD_FIELD, 6);
  if (out->day > 31) return result(SEMAP_FB_BAD_FIELD, 7);
  if (out->hour > 23) return result(SEMAP_FB_BAD_FIELD, 8);
  if (out->min > 59) return result(SEMAP_FB_BAD_FIELD, 9);
  if (out->sec > 60) return result(SEMAP_FB_BAD_FIELD, 10);
  if (out->fix_type > 5) return result(SEMAP_FB_BAD_FIELD, 20);
  if (out->lon_1e7_deg < -1800000000 || out->lon_1e7_deg > 1800000000)
    return result(SEMAP_FB_BAD_FIELD, 24);
  if (out->lat_1e7_deg < -900000000 || out->lat_1e7_deg > 900000000)
    return result(SEMAP_FB_BAD_FIELD, 28);
  return result(SEMAP_FB_OK, -1);
}

SemapFbResult semap_ubx_decode_frame(const uint8_t* frame, size_t len, SemapUbxNavPvt* out) {
  SemapUbxFrameView view;
  const SemapFbResult r = semap_ubx_check_frame(frame, len, &view);
  if (r.status != SEMAP_FB_OK) return r;
  if (view.msg_class != SEMAP_UBX_CLASS_NAV || view.msg_id != SEMAP_UBX_ID_NAV_PVT) {
    return result(SEMAP_FB_UNKNOWN, -1);
  }
  return semap_ubx_decode_nav_pvt(view.payload, view.length, out);
}

size_t semap_ubx_encode_nav_pvt(const SemapUbxNavPvt* in, uint8_t* buf, size_t cap) {
  if (cap < SEMAP_UBX_NAV_PVT_FRAME_LEN) return 0;
  memset(buf, 0, SEMAP_UBX_NAV_PVT_FRAME_LEN);
  buf[0] = SEMAP_UBX_SYNC1;
  buf[1] = SEMAP_UBX_SYNC2;
  buf[2] = SEMAP_UBX_CLASS_NAV;
  buf[3] = SEMAP_UBX_ID_NAV_PVT;
  semap_put_u16(buf + 4, SEMAP_UBX_NAV_PVT_LEN);
  uint8_t* p = buf + SEMAP_UBX_HEADER_LEN;
  semap_put_u32(p + 0, in->itow_ms);
  semap_put_u16(p + 4, in->year);
  p[6] = in->month;
  p[7] = in->day;
  p[8] = in->hour;
  p[9] = in->min;
  p[10] = in->sec;
  p[11] = in->valid;
  semap_put_u32(p + 12, in->t_acc_ns);
  semap_put_i32(p + 16, in->nano_ns);
  p[20] = in->fix_type;
  p[21] = in->flags;
  p[22] = in->flags2;
  p[23] = in->num_sv;
  semap_put_i32(p + 24, in->lon_1e7_deg);
  semap_put_i32(p + 28, in->lat_1e7_deg);
  semap_put_i32(p + 32, in->height_mm);
  semap_put_i32(p + 36, in->h_msl_mm);
  semap_put_u32(p + 40, in->h_acc_mm);
  semap_put_u32(p + 44, in->v_acc_mm);
  semap_put_i32(p + 48, in->vel_n_mm_s);
  semap_put_i32(p + 52, in->vel_e_mm_s);
  semap_put_i32(p + 56, in->vel_d_mm_s);
  semap_put_i32(p + 60, in->g_speed_mm_s);
  semap_put_i32(p + 64, in->head_mot_1e5_deg);
  semap_put_u32(p + 68, in->s_acc_mm_s);
  semap_put_u32(p + 72, in->head_acc_1e5_deg);
  semap_put_u16(p + 76, in->p_dop_001);
  p[78] = in->flags3;
  semap_put_i32(p + 84, in->head_veh_1e5_deg);
  semap_put_i16(p + 88, in->mag_dec_1e2_deg);
  semap_put_u16(p + 90, in->mag_acc_1e2_deg);
  semap_ubx_checksum(buf + 2, SEMAP_UBX_NAV_PVT_LEN + 4u, &buf[SEMAP_UBX_NAV_PVT_FRAME_LEN - 2],
                     &buf[SEMAP_UBX_NAV_PVT_FRAME_LEN - 1]);
  return SEMAP_UBX_NAV_PVT_FRAME_LEN;
}
