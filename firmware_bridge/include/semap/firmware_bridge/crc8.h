/* CRC-8/SAE-J1850 as used by the semap IMU-over-CAN protocol. Plain C99. */
#ifndef SEMAP_FIRMWARE_BRIDGE_CRC8_H
#define SEMAP_FIRMWARE_BRIDGE_CRC8_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Polynomial 0x1D, init 0xFF, no reflection, final XOR 0xFF (check "123456789" -> 0x4B).
 * The AUTOSAR E2E profile 1 CRC, chosen because CAN firmware stacks already ship it. */
#define SEMAP_CRC8_POLY 0x1Du
#define SEMAP_CRC8_INIT 0xFFu
#define SEMAP_CRC8_XOROUT 0xFFu

/* Continues a running CRC register (start with SEMAP_CRC8_INIT); no final XOR applied. */
uint8_t semap_crc8_update(uint8_t reg, const uint8_t* data, size_t len);

/* Complete CRC-8/SAE-J1850 of a buffer. */
uint8_t semap_crc8(const uint8_t* data, size_t len);

#ifdef __cplusplus
}
#endif

#endif /* SEMAP_FIRMWARE_BRIDGE_CRC8_H */
