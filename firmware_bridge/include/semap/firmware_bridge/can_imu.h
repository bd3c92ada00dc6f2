/* The semap IMU-over-CAN protocol (docs/can-protocol.md, firmware_bridge/imu.dbc). Plain C99,
 * no allocation: the same code runs in the IMU firmware and in the host driver. */
#ifndef SEMAP_FIRMWARE_BRIDGE_CAN_IMU_H
#define SEMAP_FIRMWARE_BRIDGE_CAN_IMU_H

#include <stdint.h>

#include "semap/firmware_bridge/can_frame.h"
#include "semap/firmware_bridge/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Identifiers are base + offset; the base selects the IMU node (default 0x100). */
#define SEMAP_CAN_IMU_DEFAULT_BASE_ID 0x100u
#define SEMAP_CAN_IMU_OFFSET_GYRO 0u  /* classic, 8 bytes: rates x,y,z, seq, crc */
#define SEMAP_CAN_IMU_OFFSET_ACCEL 1u /* classic, 8 bytes: accel x,y,z, seq, crc */
#define SEMAP_CAN_IMU_OFFSET_TIME 2u  /* classic, 8 bytes: timestamp_us, flags, 0, seq, crc */
#define SEMAP_CAN_IMU_OFFSET_FD 3u    /* CAN FD, 64 bytes: the whole sample */
#define SEMAP_CAN_IMU_FRAMES_PER_SAMPLE 3u
#define SEMAP_CAN_IMU_RATE_HZ 400u

/* Scaling: int16 two's complement, little-endian. 1/16 deg/s covers +-2047.9 deg/s;
 * 0.005 m/s^2 covers +-163.8 m/s^2 (+-16.7 g). */
#define SEMAP_CAN_IMU_GYRO_LSB_DPS 0.0625
#define SEMAP_CAN_IMU_ACCEL_LSB_MPS2 0.005

/* Bits of SemapImuRaw.flags. */
#define SEMAP_CAN_IMU_FLAG_GYRO_SATURATED 0x01u
#define SEMAP_CAN_IMU_FLAG_ACCEL_SATURATED 0x02u
#define SEMAP_CAN_IMU_FLAG_SENSOR_FAULT 0x04u

/* One IMU sample as it travels on the bus (body frame x forward, y left, z up). */
typedef struct SemapImuRaw {
  uint32_t timestamp_us; /* sensor clock, wraps after 2^32 us (71.6 min) */
  uint8_t sequence;      /* +1 per sample, wraps at 256 */
  uint8_t flags;
  int16_t gyro[3];  /* SEMAP_CAN_IMU_GYRO_LSB_DPS per count */
  int16_t accel[3]; /* SEMAP_CAN_IMU_ACCEL_LSB_MPS2 per count */
} SemapImuRaw;

/* Quantises SI values (rad/s, m/s^2) into `out`, clamping to the int16 range and setting the
 * saturation flags; `flags` bits other than saturation are copied from `extra_flags`. */
void semap_can_imu_quantize(const double gyro_rad_s[3], const double accel_mps2[3],
                            uint32_t timestamp_us, uint8_t sequence, uint8_t extra_flags,
                            SemapImuRaw* out);
/* The inverse: rad/s and m/s^2. */
void semap_can_imu_to_si(const SemapImuRaw* raw, double gyro_rad_s[3], double accel_mps2[3]);

/* Encodes one sample as the three classic frames (gyro, accel, time), in that order. */
void semap_can_imu_encode(const SemapImuRaw* raw, uint32_t base_id,
                          SemapCanFrame out[SEMAP_CAN_IMU_FRAMES_PER_SAMPLE]);
/* Encodes one sample as a single 64-byte CAN FD frame. */
void semap_can_imu_encode_fd(const SemapImuRaw* raw, uint32_t base_id, SemapCanFrame* out);

/* Which frame of the protocol a decoded frame was. */
typedef enum SemapCanImuPartKind {
  SEMAP_CAN_IMU_PART_GYRO = 0,
  SEMAP_CAN_IMU_PART_ACCEL = 1,
  SEMAP_CAN_IMU_PART_TIME = 2,
  SEMAP_CAN_IMU_PART_FD = 3
} SemapCanImuPartKind;

/* One decoded frame; only the fields of its kind are filled (FD fills all). */
typedef struct SemapCanImuPart {
  SemapCanImuPartKind kind;
  SemapImuRaw raw;
} SemapCanImuPart;

/* Decodes a single frame: UNKNOWN for an identifier outside base..base+3 or an extended id,
 * TRUNCATED for a wrong length, BAD_CHECKSUM for a CRC mismatch, BAD_FIELD (byte 5) for a
 * non-zero reserved byte. */
SemapFbResult semap_can_imu_decode(const SemapCanFrame* frame, uint32_t base_id,
                                   SemapCanImuPart* out);

/* A complete sample with the wrapping counters extended to 32/64 bits. */
typedef struct SemapCanImuSample {
  SemapImuRaw raw;
  uint32_t sequence;     /* unwrapped: counts every sample the sensor produced since start */
  uint64_t timestamp_us; /* unwrapped sensor time */
} SemapCanImuSample;

typedef struct SemapCanImuCounters {
  uint32_t frames;         /* frames carrying one of our identifiers */
  uint32_t samples;        /* complete samples delivered */
  uint32_t crc_errors;     /* frames rejected by CRC-8 */
  uint32_t bad_frames;     /* frames rejected for length or reserved bits */
  uint32_t incomplete;     /* samples abandoned because one of their frames never came */
  uint32_t sequence_gaps;  /* times the sequence of delivered samples jumped */
  uint32_t missed_samples; /* sum of the jumps: samples the sensor made that we never got */
} SemapCanImuCounters;

/* Pairs the gyro/accel/time frames of one sample by sequence number (frames may arrive in any
 * order, but samples are not interleaved) and checks sequence continuity between samples. */
typedef struct SemapCanImuAssembler {
  uint32_t base_id;
  SemapImuRaw pending;
  uint8_t pending_mask; /* bit per SemapCanImuPartKind received for `pending.sequence` */
  uint8_t started;      /* a sample has been delivered, so `last_*` are meaningful */
  uint8_t last_sequence;
  uint32_t last_timestamp_us;
  uint32_t sequence;
  uint64_t timestamp_us;
  SemapCanImuCounters counters;
} SemapCanImuAssembler;

void semap_can_imu_assembler_init(SemapCanImuAssembler* a, uint32_t base_id);

/* Feeds one frame. OK: `out` holds a complete sample. NEED_MORE: frame accepted, sample not yet
 * complete. Any other status: frame rejected (and counted unless UNKNOWN). */
SemapFbResult semap_can_imu_assembler_push(SemapCanImuAssembler* a, const SemapCanFrame* frame,
                                           SemapCanImuSample* out);

#ifdef __cplusplus
}
#endif

#endif /* SEMAP_FIRMWARE_BRIDGE_CAN_IMU_H */
