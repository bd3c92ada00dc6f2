#include "semap/firmware_bridge/j1939.h"

#include <string.h>

#include "bytes.h"

#define SEMAP_J1939_PDU2_MIN_PF 240u
#define SEMAP_J1939_LATENCY_MAX_RAW 250u

static SemapFbResult result(SemapFbStatus status, int16_t field) {
  SemapFbResult r;
  r.status = status;
  r.field = field;
  return r;
}

SemapJ1939Id semap_j1939_parse_id(uint32_t id29) {
  SemapJ1939Id id;
  const uint32_t pf = (id29 >> 16) & 0xFFu;
  const uint32_t ps = (id29 >> 8) & 0xFFu;
  const uint32_t dp = (id29 >> 24) & 0x03u; /* extended data page and data page */
  id.priority = (uint8_t)((id29 >> 26) & 0x07u);
  id.source = (uint8_t)(id29 & 0xFFu);
  if (pf >= SEMAP_J1939_PDU2_MIN_PF) {
    id.pgn = (dp << 16) | (pf << 8) | ps;
    id.destination = 0xFFu;
  } else {
    id.pgn = (dp << 16) | (pf << 8);
    id.destination = (uint8_t)ps;
  }
  return id;
}

uint32_t semap_j1939_make_id(uint8_t priority, uint32_t pgn, uint8_t source) {
  return ((uint32_t)(priority & 0x07u) << 26) | ((pgn & 0x3FFFFu) << 8) | source;
}

/* Decodes a 16-bit SPN; returns 0 when the raw value is an error / not-available indicator. */
static int get_scaled(const uint8_t* p, double lsb, double offset, double* out) {
  const uint16_t raw = semap_get_u16(p);
  if (raw > SEMAP_J1939_MAX_VALID_U16) return 0;
  *out = raw * lsb + offset;
  return 1;
}

static void put_scaled(uint8_t* p, double value, double lsb, double offset) {
  int clamped = 0;
  semap_put_u16(p, (uint16_t)semap_round_clamp((value - offset) / lsb, 0, SEMAP_J1939_MAX_VALID_U16,
                                               &clamped));
}

SemapFbResult semap_j1939_decode_angular_rate(const uint8_t* data, uint8_t len,
                                              SemapJ1939AngularRate* out) {
  if (len < 8) return result(SEMAP_FB_TRUNCATED, -1);
  if (!get_scaled(data, SEMAP_J1939_RATE_LSB_DPS, SEMAP_J1939_RATE_OFFSET_DPS, &out->pitch_dps))
    return result(SEMAP_FB_BAD_FIELD, 0);
  if (!get_scaled(data + 2, SEMAP_J1939_RATE_LSB_DPS, SEMAP_J1939_RATE_OFFSET_DPS, &out->roll_dps))
    return result(SEMAP_FB_BAD_FIELD, 2);
  if (!get_scaled(data + 4, SEMAP_J1939_RATE_LSB_DPS, SEMAP_J1939_RATE_OFFSET_DPS, &out->yaw_dps))
    return result(SEMAP_FB_BAD_FIELD, 4);
  out->pitch_fom = data[6] & 0x03u;
  out->roll_fom = (data[6] >> 2) & 0x03u;
  out->yaw_fom = (data[6] >> 4) & 0x03u;
  out->latency_ms =
      data[7] <= SEMAP_J1939_LATENCY_MAX_RAW ? data[7] * SEMAP_J1939_LATENCY_LSB_MS : -1.0;
  return result(SEMAP_FB_OK, -1);
}

SemapFbResult semap_j1939_decode_acceleration(const uint8_t* data, uint8_t len,
                                              SemapJ1939Acceleration* out) {
  if (len < 8) return result(SEMAP_FB_TRUNCATED, -1);
  if (!get_scaled(data, SEMAP_J1939_ACCEL_LSB_MPS2, SEMAP_J1939_ACCEL_OFFSET_MPS2,
                  &out->lateral_mps2))
    return result(SEMAP_FB_BAD_FIELD, 0);
  if (!get_scaled(data + 2, SEMAP_J1939_ACCEL_LSB_MPS2, SEMAP_J1939_ACCEL_OFFSET_MPS2,
                  &out->longitudinal_mps2))
    return result(SEMAP_FB_BAD_FIELD, 2);
  if (!get_scaled(data + 4, SEMAP_J1939_ACCEL_LSB_MPS2, SEMAP_J1939_ACCEL_OFFSET_MPS2,
                  &out->vertical_mps2))
    return result(SEMAP_FB_BAD_FIELD, 4);
  out->lateral_fom = data[6] & 0x03u;
  out->longitudinal_fom = (data[6] >> 2) & 0x03u;
  out->vertical_fom = (data[6] >> 4) & 0x03u;
  return result(SEMAP_FB_OK, -1);
}

static void start_frame(SemapCanFrame* f, uint8_t priority, uint32_t pgn, uint8_t source) {
  memset(f, 0, sizeof *f);
  f->id = semap_j1939_make_id(priority, pgn, source);
  f->extended = 1;
  f->len = 8;
}

void semap_j1939_encode_angular_rate(const SemapJ1939AngularRate* in, uint8_t priority,
                                     uint8_t source, SemapCanFrame* out) {
  start_frame(out, priority, SEMAP_J1939_PGN_ANGULAR_RATE, source);
  put_scaled(out->data, in->pitch_dps, SEMAP_J1939_RATE_LSB_DPS, SEMAP_J1939_RATE_OFFSET_DPS);
  put_scaled(out->data + 2, in->roll_dps, SEMAP_J1939_RATE_LSB_DPS, SEMAP_J1939_RATE_OFFSET_DPS);
  put_scaled(out->data + 4, in->yaw_dps, SEMAP_J1939_RATE_LSB_DPS, SEMAP_J1939_RATE_OFFSET_DPS);
  /* Bits 6-7 of byte 6 are reserved and sent as 1, as J1939 requires. */
  out->data[6] = (uint8_t)(0xC0u | (in->pitch_fom & 0x03u) | ((in->roll_fom & 0x03u) << 2) |
                           ((in->yaw_fom & 0x03u) << 4));
  if (in->latency_ms < 0.0) {
    out->data[7] = 0xFFu;
  } else {
    int clamped = 0;
    out->data[7] = (uint8_t)semap_round_clamp(in->latency_ms / SEMAP_J1939_LATENCY_LSB_MS, 0,
                                              SEMAP_J1939_LATENCY_MAX_RAW, &clamped);
  }
}

void semap_j1939_encode_acceleration(const SemapJ1939Acceleration* in, uint8_t priority,
                                     uint8_t source, SemapCanFrame* out) {
  start_frame(out, priority, SEMAP_J1939_PGN_ACCELERATION, source);
  put_scaled(out->data, in->lateral_mps2, SEMAP_J1939_ACCEL_LSB_MPS2,
             SEMAP_J1939_ACCEL_OFFSET_MPS2);
  put_scaled(out->data + 2, in->longitudinal_mps2, SEMAP_J1939_ACCEL_LSB_MPS2,
             SEMAP_J1939_ACCEL_OFFSET_MPS2);
  put_scaled(out->data + 4, in->vertical_mps2, SEMAP_J1939_ACCEL_LSB_MPS2,
             SEMAP_J1939_ACCEL_OFFSET_MPS2);
  out->data[6] =
      (uint8_t)(0xC0u | (in->lateral_fom & 0x03u) | ((in->longitudinal_fom & 0x03u) << 2) |
                ((in->vertical_fom & 0x03u) << 4));
  out->data[7] = 0xFFu;
}

void semap_j1939_imu_assembler_init(SemapJ1939ImuAssembler* a, uint16_t source) {
  memset(a, 0, sizeof *a);
  a->source = source;
}

SemapFbResult semap_j1939_imu_assembler_push(SemapJ1939ImuAssembler* a, const SemapCanFrame* frame,
                                             SemapJ1939AngularRate* rate,
                                             SemapJ1939Acceleration* accel) {
  if (!frame->extended) return result(SEMAP_FB_UNKNOWN, -1);
  const SemapJ1939Id id = semap_j1939_parse_id(frame->id);
  const int is_rate = id.pgn == SEMAP_J1939_PGN_ANGULAR_RATE;
  if ((!is_rate && id.pgn != SEMAP_J1939_PGN_ACCELERATION) ||
      (a->source != SEMAP_J1939_ADDRESS_ANY && id.source != a->source)) {
    return result(SEMAP_FB_UNKNOWN, -1);
  }
  a->counters.frames++;
  SemapFbResult r;
  if (is_rate) {
    SemapJ1939AngularRate decoded;
    r = semap_j1939_decode_angular_rate(frame->data, frame->len, &decoded);
    if (r.status == SEMAP_FB_OK) {
      if (a->have_rate) a->counters.unpaired++;
      a->rate = decoded;
      a->have_rate = 1;
    }
  } else {
    SemapJ1939Acceleration decoded;
    r = semap_j1939_decode_acceleration(frame->data, frame->len, &decoded);
    if (r.status == SEMAP_FB_OK) {
      if (a->have_accel) a->counters.unpaired++;
      a->accel = decoded;
      a->have_accel = 1;
    }
  }
  if (r.status != SEMAP_FB_OK) {
    a->counters.bad_frames++;
    return r;
  }
  if (!(a->have_rate && a->have_accel)) return result(SEMAP_FB_NEED_MORE, -1);
  *rate = a->rate;
  *accel = a->accel;
  a->have_rate = 0;
  a->have_accel = 0;
  a->counters.samples++;
  return r;
}
