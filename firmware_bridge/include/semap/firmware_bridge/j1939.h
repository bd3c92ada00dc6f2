/* SAE J1939 Angular Rate (ARI, PGN 61482) and Acceleration (ACCS, PGN 61485) for
 * off-the-shelf J1939 IMUs. Plain C99, no allocation. */
#ifndef SEMAP_FIRMWARE_BRIDGE_J1939_H
#define SEMAP_FIRMWARE_BRIDGE_J1939_H

#include <stdint.h>

#include "semap/firmware_bridge/can_frame.h"
#include "semap/firmware_bridge/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SEMAP_J1939_PGN_ANGULAR_RATE 61482u /* 0xF02A */
#define SEMAP_J1939_PGN_ACCELERATION 61485u /* 0xF02D */
#define SEMAP_J1939_ADDRESS_ANY 0xFFFFu

/* Standard scaling of the rate and acceleration SPNs. */
#define SEMAP_J1939_RATE_LSB_DPS (1.0 / 128.0)
#define SEMAP_J1939_RATE_OFFSET_DPS (-250.0)
#define SEMAP_J1939_ACCEL_LSB_MPS2 0.01
#define SEMAP_J1939_ACCEL_OFFSET_MPS2 (-320.0)
/* 16-bit raw values above this are J1939 error / not-available indicators. */
#define SEMAP_J1939_MAX_VALID_U16 0xFAFFu
#define SEMAP_J1939_LATENCY_LSB_MS 0.5

/* Fields of a 29-bit identifier. */
typedef struct SemapJ1939Id {
  uint8_t priority;    /* 0..7 */
  uint32_t pgn;        /* 18-bit parameter group number (PDU1: destination removed) */
  uint8_t source;      /* source address */
  uint8_t destination; /* PDU1 destination, 0xFF (global) for PDU2 */
} SemapJ1939Id;

SemapJ1939Id semap_j1939_parse_id(uint32_t id29);
uint32_t semap_j1939_make_id(uint8_t priority, uint32_t pgn, uint8_t source);

/* Figures of merit: 0 fully functional, 1 degraded, 2 error, 3 not available. */
typedef struct SemapJ1939AngularRate {
  double pitch_dps; /* about the lateral axis */
  double roll_dps;  /* about the longitudinal axis */
  double yaw_dps;   /* about the vertical axis */
  uint8_t pitch_fom, roll_fom, yaw_fom;
  double latency_ms; /* negative when not available */
} SemapJ1939AngularRate;

typedef struct SemapJ1939Acceleration {
  double lateral_mps2;
  double longitudinal_mps2;
  double vertical_mps2;
  uint8_t lateral_fom, longitudinal_fom, vertical_fom;
} SemapJ1939Acceleration;

/* Payload decoders (8 bytes). TRUNCATED for a short payload; BAD_FIELD with the byte offset of
 * a value flagged as error / not available. */
SemapFbResult semap_j1939_decode_angular_rate(const uint8_t* data, uint8_t len,
                                              SemapJ1939AngularRate* out);
SemapFbResult semap_j1939_decode_acceleration(const uint8_t* data, uint8_t len,
                                              SemapJ1939Acceleration* out);

/* Encoders (for emulators and tests); values are clamped to the valid raw range. */
void semap_j1939_encode_angular_rate(const SemapJ1939AngularRate* in, uint8_t priority,
                                     uint8_t source, SemapCanFrame* out);
void semap_j1939_encode_acceleration(const SemapJ1939Acceleration* in, uint8_t priority,
                                     uint8_t source, SemapCanFrame* out);

typedef struct SemapJ1939ImuCounters {
  uint32_t frames;     /* ARI/ACCS frames from the accepted source */
  uint32_t samples;    /* rate+acceleration pairs delivered */
  uint32_t bad_frames; /* truncated or flagged values */
  uint32_t unpaired;   /* a message replaced before its partner arrived */
} SemapJ1939ImuCounters;

/* Pairs one ARI with the next ACCS (either order) from one source into a sample. */
typedef struct SemapJ1939ImuAssembler {
  uint16_t source; /* accepted source address, or SEMAP_J1939_ADDRESS_ANY */
  SemapJ1939AngularRate rate;
  SemapJ1939Acceleration accel;
  uint8_t have_rate, have_accel;
  SemapJ1939ImuCounters counters;
} SemapJ1939ImuAssembler;

void semap_j1939_imu_assembler_init(SemapJ1939ImuAssembler* a, uint16_t source);

/* OK: `rate` and `accel` hold a pair. NEED_MORE: stored, waiting for the partner. UNKNOWN: not
 * an extended frame, another PGN or another source. Other statuses: rejected and counted. */
SemapFbResult semap_j1939_imu_assembler_push(SemapJ1939ImuAssembler* a, const SemapCanFrame* frame,
                                             SemapJ1939AngularRate* rate,
                                             SemapJ1939Acceleration* accel);

#ifdef __cplusplus
}
#endif

#endif /* SEMAP_FIRMWARE_BRIDGE_J1939_H */
