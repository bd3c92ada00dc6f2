/* Little-endian field access shared by the C codecs (private to firmware_bridge). */
#ifndef SEMAP_FIRMWARE_BRIDGE_SRC_BYTES_H
#define SEMAP_FIRMWARE_BRIDGE_SRC_BYTES_H

#include <stdint.h>

static inline uint16_t semap_get_u16(const uint8_t* p) {
  return (uint16_t)(p[0] | (uint16_t)(p[1] << 8));
}
static inline uint32_t semap_get_u32(const uint8_t* p) {
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static inline int16_t semap_get_i16(const uint8_t* p) { return (int16_t)semap_get_u16(p); }
static inline int32_t semap_get_i32(const uint8_t* p) { return (int32_t)semap_get_u32(p); }

static inline void semap_put_u16(uint8_t* p, uint16_t v) {
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)(v >> 8);
}
static inline void semap_put_u32(uint8_t* p, uint32_t v) {
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)((v >> 8) & 0xFFu);
  p[2] = (uint8_t)((v >> 16) & 0xFFu);
  p[3] = (uint8_t)(v >> 24);
}
static inline void semap_put_i16(uint8_t* p, int16_t v) { semap_put_u16(p, (uint16_t)v); }
static inline void semap_put_i32(uint8_t* p, int32_t v) { semap_put_u32(p, (uint32_t)v); }

/* Rounds half away from zero and clamps to [lo, hi]; sets *clamped when it had to (NaN -> 0). */
static inline long semap_round_clamp(double v, long lo, long hi, int* clamped) {
  const double r = v >= 0.0 ? v + 0.5 : v - 0.5; /* truncation below completes the rounding */
  if (r != r) {
    *clamped = 1;
    return 0;
  }
  if (r >= (double)hi + 1.0) {
    *clamped = 1;
    return hi;
  }
  if (r <= (double)lo - 1.0) {
    *clamped = 1;
    return lo;
  }
  return (long)r;
}

#endif /* SEMAP_FIRMWARE_BRIDGE_SRC_BYTES_H */
