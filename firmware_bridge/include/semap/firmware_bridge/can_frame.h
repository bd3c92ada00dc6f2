/* A bus-neutral CAN / CAN FD frame, so codecs need neither Linux nor an MCU HAL. Plain C99. */
#ifndef SEMAP_FIRMWARE_BRIDGE_CAN_FRAME_H
#define SEMAP_FIRMWARE_BRIDGE_CAN_FRAME_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SEMAP_CAN_MAX_DLEN 8u
#define SEMAP_CANFD_MAX_DLEN 64u

typedef struct SemapCanFrame {
  uint32_t id;      /* 11-bit (standard) or 29-bit (extended) identifier, no flag bits */
  uint8_t extended; /* 1 for a 29-bit identifier */
  uint8_t fd;       /* 1 for a CAN FD frame */
  uint8_t len;      /* payload bytes: 0..8 classic, 0..64 FD */
  uint8_t data[SEMAP_CANFD_MAX_DLEN];
} SemapCanFrame;

#ifdef __cplusplus
}
#endif

#endif /* SEMAP_FIRMWARE_BRIDGE_CAN_FRAME_H */
