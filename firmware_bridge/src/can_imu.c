#include "semap/firmware_bridge/can_imu.h"

#include <string.h>

#include "bytes.h"
#include "semap/firmware_bridge/crc8.h"

#define SEMAP_PI 3.14159265358979323846
#define SEMAP_CLASSIC_LEN 8u
#define SEMAP_SEQ_BYTE 6u
#define SEMAP_FD_SEQ_BYTE 5u

/* The CRC covers the 11-bit identifier (two bytes, big-endian) before the payload, so a frame
 * delivered under the wrong identifier fails the check too. */
static uint8_t frame_crc(uint32_t id, const uint8_t* data, size_t len) {
  const uint8_t id_bytes[2] = {(uint8_t)((id >> 8) & 0x07u), (uint8_t)(id & 0xFFu)};
  uint8_t reg = semap_crc8_update(SEMAP_CRC8_INIT, id_bytes, sizeof id_bytes);
  reg = semap_crc8_update(reg, data, len);
  return (uint8_t)(reg ^ SEMAP_CRC8_XOROUT);
}

void semap_can_imu_quantize(const double gyro_rad_s[3], const double accel_mps2[3],
                            uint32_t timestamp_us, uint8_t sequence, uint8_t extra_flags,
                            SemapImuRaw* out) {
  int gyro_clamped = 0;
  int accel_clamped = 0;
  for (int i = 0; i < 3; ++i) {
    const double dps = gyro_rad_s[i] * (180.0 / SEMAP_PI);
    out->gyro[i] =
        (int16_t)semap_round_clamp(dps / SEMAP_CAN_IMU_GYRO_LSB_DPS, -32768, 32767, &gyro_clamped);
    out->accel[i] = (int16_t)semap_round_clamp(accel_mps2[i] / SEMAP_CAN_IMU_ACCEL_LSB_MPS2, -32768,
                                               32767, &accel_clamped);
  }
  out->timestamp_us = timestamp_us;
  out->sequence = sequence;
  out->flags = (uint8_t)(extra_flags &
                         ~(SEMAP_CAN_IMU_FLAG_GYRO_SATURATED | SEMAP_CAN_IMU_FLAG_ACCEL_SATURATED));
  if (gyro_clamped) out->flags |= SEMAP_CAN_IMU_FLAG_GYRO_SATURATED;
  if (accel_clamped) out->flags |= SEMAP_CAN_IMU_FLAG_ACCEL_SATURATED;
}

void semap_can_imu_to_si(const SemapImuRaw* raw, double gyro_rad_s[3], double accel_mps2[3]) {
  for (int i = 0; i < 3; ++i) {
    gyro_rad_s[i] = raw->gyro[i] * SEMAP_CAN_IMU_GYRO_LSB_DPS * (SEMAP_PI / 180.0);
    accel_mps2[i] = raw->accel[i] * SEMAP_CAN_IMU_ACCEL_LSB_MPS2;
  }
}

static void start_frame(SemapCanFrame* f, uint32_t id, uint8_t len, uint8_t fd) {
  memset(f, 0, sizeof *f);
  f->id = id & 0x7FFu;
  f->len = len;
  f->fd = fd;
}

static void put_vector(uint8_t* p, const int16_t v[3]) {
  for (int i = 0; i < 3; ++i) semap_put_i16(p + 2 * i, v[i]);
}

static void get_vector(const uint8_t* p, int16_t v[3]) {
  for (int i = 0; i < 3; ++i) v[i] = semap_get_i16(p + 2 * i);
}

void semap_can_imu_encode(const SemapImuRaw* raw, uint32_t base_id,
                          SemapCanFrame out[SEMAP_CAN_IMU_FRAMES_PER_SAMPLE]) {
  start_frame(&out[0], base_id + SEMAP_CAN_IMU_OFFSET_GYRO, SEMAP_CLASSIC_LEN, 0);
  put_vector(out[0].data, raw->gyro);
  start_frame(&out[1], base_id + SEMAP_CAN_IMU_OFFSET_ACCEL, SEMAP_CLASSIC_LEN, 0);
  put_vector(out[1].data, raw->accel);
  start_frame(&out[2], base_id + SEMAP_CAN_IMU_OFFSET_TIME, SEMAP_CLASSIC_LEN, 0);
  semap_put_u32(out[2].data, raw->timestamp_us);
  out[2].data[4] = raw->flags;
  for (unsigned i = 0; i < SEMAP_CAN_IMU_FRAMES_PER_SAMPLE; ++i) {
    out[i].data[SEMAP_SEQ_BYTE] = raw->sequence;
    out[i].data[7] = frame_crc(out[i].id, out[i].data, 7);
  }
}

void semap_can_imu_encode_fd(const SemapImuRaw* raw, uint32_t base_id, SemapCanFrame* out) {
  start_frame(out, base_id + SEMAP_CAN_IMU_OFFSET_FD, SEMAP_CANFD_MAX_DLEN, 1);
  semap_put_u32(out->data, raw->timestamp_us);
  out->data[4] = raw->flags;
  out->data[SEMAP_FD_SEQ_BYTE] = raw->sequence;
  put_vector(out->data + 6, raw->gyro);
  put_vector(out->data + 12, raw->accel);
  out->data[63] = frame_crc(out->id, out->data, 63);
}

static SemapFbResult result(SemapFbStatus status, int16_t field) {
  SemapFbResult r;
  r.status = status;
  r.field = field;
  return r;
}

SemapFbResult semap_can_imu_decode(const SemapCanFrame* frame, uint32_t base_id,
                                   SemapCanImuPart* out) {
  const uint32_t offset = frame->id - base_id; /* wraps to a large value below base */
  if (frame->extended || offset > SEMAP_CAN_IMU_OFFSET_FD) return result(SEMAP_FB_UNKNOWN, -1);
  const uint8_t expected =
      offset == SEMAP_CAN_IMU_OFFSET_FD ? SEMAP_CANFD_MAX_DLEN : SEMAP_CLASSIC_LEN;
  if (frame->len < expected) return result(SEMAP_FB_TRUNCATED, -1);
  if (frame->len > expected) return result(SEMAP_FB_TOO_LONG, -1);
  if (frame_crc(frame->id, frame->data, expected - 1u) != frame->data[expected - 1u]) {
    return result(SEMAP_FB_BAD_CHECKSUM, (int16_t)(expected - 1u));
  }
  memset(out, 0, sizeof *out);
  out->kind = (SemapCanImuPartKind)offset;
  const uint8_t* d = frame->data;
  switch (out->kind) {
    case SEMAP_CAN_IMU_PART_GYRO:
      get_vector(d, out->raw.gyro);
      out->raw.sequence = d[SEMAP_SEQ_BYTE];
      break;
    case SEMAP_CAN_IMU_PART_ACCEL:
      get_vector(d, out->raw.accel);
      out->raw.sequence = d[SEMAP_SEQ_BYTE];
      break;
    case SEMAP_CAN_IMU_PART_TIME:
      if (d[5] != 0) return result(SEMAP_FB_BAD_FIELD, 5);
      out->raw.timestamp_us = semap_get_u32(d);
      out->raw.flags = d[4];
      out->raw.sequence = d[SEMAP_SEQ_BYTE];
      break;
    case SEMAP_CAN_IMU_PART_FD:
      out->raw.timestamp_us = semap_get_u32(d);
      out->raw.flags = d[4];
      out->raw.sequence = d[SEMAP_FD_SEQ_BYTE];
      get_vector(d + 6, out->raw.gyro);
      get_vector(d + 12, out->raw.accel);
      break;
  }
  return result(SEMAP_FB_OK, -1);
}

void semap_can_imu_assembler_init(SemapCanImuAssembler* a, uint32_t base_id) {
  memset(a, 0, sizeof *a);
  a->base_id = base_id;
}

static void complete(SemapCanImuAssembler* a, const SemapImuRaw* raw, SemapCanImuSample* out) {
  if (!a->started) {
    a->started = 1;
    a->sequence = raw->sequence;
    a->timestamp_us = raw->timestamp_us;
  } else {
    /* Modular differences extend the 8-bit sequence and the 32-bit microsecond clock. */
    const uint8_t step = (uint8_t)(raw->sequence - a->last_sequence);
    if (step != 1u) {
      a->counters.sequence_gaps++;
      a->counters.missed_samples += (uint8_t)(step - 1u);
    }
    a->sequence += step;
    a->timestamp_us += (uint32_t)(raw->timestamp_us - a->last_timestamp_us);
  }
  a->last_sequence = raw->sequence;
  a->last_timestamp_us = raw->timestamp_us;
  a->counters.samples++;
  out->raw = *raw;
  out->sequence = a->sequence;
  out->timestamp_us = a->timestamp_us;
}

SemapFbResult semap_can_imu_assembler_push(SemapCanImuAssembler* a, const SemapCanFrame* frame,
                                           SemapCanImuSample* out) {
  SemapCanImuPart part;
  SemapFbResult r = semap_can_imu_decode(frame, a->base_id, &part);
  if (r.status == SEMAP_FB_UNKNOWN) return r;
  a->counters.frames++;
  if (r.status == SEMAP_FB_BAD_CHECKSUM) {
    a->counters.crc_errors++;
    return r;
  }
  if (r.status != SEMAP_FB_OK) {
    a->counters.bad_frames++;
    return r;
  }
  if (a->pending_mask != 0 &&
      (part.kind == SEMAP_CAN_IMU_PART_FD || part.raw.sequence != a->pending.sequence)) {
    a->counters.incomplete++;
    a->pending_mask = 0;
  }
  if (part.kind == SEMAP_CAN_IMU_PART_FD) {
    complete(a, &part.raw, out);
    return r;
  }
  if (a->pending_mask == 0) {
    memset(&a->pending, 0, sizeof a->pending);
    a->pending.sequence = part.raw.sequence;
  }
  switch (part.kind) {
    case SEMAP_CAN_IMU_PART_GYRO:
      memcpy(a->pending.gyro, part.raw.gyro, sizeof a->pending.gyro);
      break;
    case SEMAP_CAN_IMU_PART_ACCEL:
      memcpy(a->pending.accel, part.raw.accel, sizeof a->pending.accel);
      break;
    default:
      a->pending.timestamp_us = part.raw.timestamp_us;
      a->pending.flags = part.raw.flags;
      break;
  }
  a->pending_mask |= (uint8_t)(1u << part.kind);
  if (a->pending_mask != 0x07u) return result(SEMAP_FB_NEED_MORE, -1);
  a->pending_mask = 0;
  complete(a, &a->pending, out);
  return r;
}
