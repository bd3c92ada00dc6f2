/* One line of a `candump -L` log, the format can-utils' canplayer replays:
 *   (1700000000.123456) can0 0CF02A80#007D807D00002404
 * Classic frames `ID#DATA` (3 hex digits for 11-bit ids, 8 for 29-bit), remote frames `ID#R`,
 * CAN FD frames `ID##<flags nibble>DATA`, error frames with CAN_ERR_FLAG (0x20000000) in an
 * 8-digit id. Plain C99, no allocation. */
#ifndef SEMAP_FIRMWARE_BRIDGE_CANDUMP_LOG_H
#define SEMAP_FIRMWARE_BRIDGE_CANDUMP_LOG_H

#include <stddef.h>
#include <stdint.h>

#include "semap/firmware_bridge/can_frame.h"
#include "semap/firmware_bridge/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SEMAP_CANDUMP_MAX_INTERFACE 15u /* IFNAMSIZ - 1 */
/* Longest line the formatter writes is 185 characters (FD, 64 bytes); longer input is damage. */
#define SEMAP_CANDUMP_MAX_LINE 255u
#define SEMAP_CANDUMP_ERR_FLAG 0x20000000u /* CAN_ERR_FLAG as candump prints it */
#define SEMAP_CANDUMP_ERR_MASK 0x1FFFFFFFu /* error class bits of an error frame's id */

typedef enum SemapCandumpKind {
  SEMAP_CANDUMP_DATA = 0,
  SEMAP_CANDUMP_REMOTE, /* RTR: frame.len holds the requested length, no data */
  SEMAP_CANDUMP_ERROR   /* error frame: frame.id holds the error class bits, data the details */
} SemapCandumpKind;

/* Which part of a line a SEMAP_FB_* result's `field` names. */
typedef enum SemapCandumpField {
  SEMAP_CANDUMP_FIELD_TIMESTAMP = 0,
  SEMAP_CANDUMP_FIELD_INTERFACE,
  SEMAP_CANDUMP_FIELD_ID,
  SEMAP_CANDUMP_FIELD_FD_FLAGS,
  SEMAP_CANDUMP_FIELD_DATA,
  SEMAP_CANDUMP_FIELD_TRAILER, /* what follows the frame: nothing, or a direction R / T / D */
  SEMAP_CANDUMP_FIELD_COUNT
} SemapCandumpField;

typedef struct SemapCandumpRecord {
  uint64_t seconds; /* receive time, CLOCK_REALTIME as candump prints it */
  uint32_t microseconds;
  char interface[SEMAP_CANDUMP_MAX_INTERFACE + 1];
  uint8_t kind;     /* SemapCandumpKind */
  uint8_t fd_flags; /* CAN FD: 0x01 bit rate switch, 0x02 error state indicator */
  SemapCanFrame frame;
} SemapCandumpRecord;

/* Parses one line without its newline (a trailing '\r' or blanks are allowed). OK, or
 * TRUNCATED (the line ends before the frame is complete), TOO_LONG (more data than the frame
 * holds, a longer interface name or line), BAD_FIELD; `field` is a SemapCandumpField. */
SemapFbResult semap_candump_parse_line(const char* line, size_t len, SemapCandumpRecord* out);

/* Writes the record as one line with its newline and a terminating NUL, as candump -L does.
 * Returns the characters written (without the NUL), or 0 when `capacity` is too small or the
 * record cannot be written (length beyond its kind's maximum, empty or long interface name). */
size_t semap_candump_format_line(const SemapCandumpRecord* in, char* out, size_t capacity);

/* "timestamp", "interface", "id", "fd_flags", "data", "trailer". */
const char* semap_candump_field_name(int16_t field);

#ifdef __cplusplus
}
#endif

#endif /* SEMAP_FIRMWARE_BRIDGE_CANDUMP_LOG_H */
