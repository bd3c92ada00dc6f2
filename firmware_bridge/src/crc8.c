#include "semap/firmware_bridge/crc8.h"

/* Bitwise rather than table-driven: 8 shifts per byte are cheap at 1200 frames/s and keep the
 * firmware image free of a 256-byte table. */
uint8_t semap_crc8_update(uint8_t reg, const uint8_t* data, size_t len) {
  for (size_t i = 0; i < len; ++i) {
    reg ^= data[i];
    for (int bit = 0; bit < 8; ++bit) {
      reg = (reg & 0x80u) ? (uint8_t)((reg << 1) ^ SEMAP_CRC8_POLY) : (uint8_t)(reg << 1);
    }
  }
  return reg;
}

uint8_t semap_crc8(const uint8_t* data, size_t len) {
  return (uint8_t)(semap_crc8_update(SEMAP_CRC8_INIT, data, len) ^ SEMAP_CRC8_XOROUT);
}
