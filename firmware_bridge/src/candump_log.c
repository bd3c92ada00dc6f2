#include "semap/firmware_bridge/candump_log.h"

#include <stdio.h>
#include <string.h>

#define SEMAP_CANDUMP_MAX_SECONDS_DIGITS 19u /* fits uint64_t */
#define SEMAP_CANDUMP_SFF_DIGITS 3u
#define SEMAP_CANDUMP_EFF_DIGITS 8u
#define SEMAP_CANDUMP_EFF_MASK 0x1FFFFFFFu

static SemapFbResult result(SemapFbStatus status, int16_t field) {
  SemapFbResult r;
  r.status = status;
  r.field = field;
  return r;
}

static int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

static int is_blank(char c) { return c == ' ' || c == '\t'; }

/* The lengths a CAN FD frame can have (DLC 0..15). */
static int is_fd_length(size_t n) {
  return n <= 8u || n == 12u || n == 16u || n == 20u || n == 24u || n == 32u || n == 48u ||
         n == 64u;
}

/* Parses "(SECONDS.MICROS)" at line[*i]; advances *i past the ')'. */
static SemapFbResult parse_timestamp(const char* line, size_t len, size_t* i,
                                     SemapCandumpRecord* out) {
  const int16_t field = SEMAP_CANDUMP_FIELD_TIMESTAMP;
  size_t p = *i;
  if (p == len) return result(SEMAP_FB_TRUNCATED, field);
  if (line[p++] != '(') return result(SEMAP_FB_BAD_FIELD, field);
  size_t digits = 0;
  while (p < len && line[p] >= '0' && line[p] <= '9') {
    if (++digits > SEMAP_CANDUMP_MAX_SECONDS_DIGITS) return result(SEMAP_FB_TOO_LONG, field);
    out->seconds = out->seconds * 10u + (uint64_t)(line[p++] - '0');
  }
  if (p == len) return result(SEMAP_FB_TRUNCATED, field);
  if (digits == 0 || line[p++] != '.') return result(SEMAP_FB_BAD_FIELD, field);
  /* Exactly six digits, as candump writes and canplayer requires. */
  for (digits = 0; digits < 6u; ++digits, ++p) {
    if (p == len) return result(SEMAP_FB_TRUNCATED, field);
    if (line[p] < '0' || line[p] > '9') return result(SEMAP_FB_BAD_FIELD, field);
    out->microseconds = out->microseconds * 10u + (uint32_t)(line[p] - '0');
  }
  if (p == len) return result(SEMAP_FB_TRUNCATED, field);
  if (line[p++] != ')') return result(SEMAP_FB_BAD_FIELD, field);
  *i = p;
  return result(SEMAP_FB_OK, -1);
}

/* Hex bytes, optionally separated by '.', up to `max`; sets frame->len. */
static SemapFbResult parse_data(const char* s, size_t n, size_t max, SemapCanFrame* frame) {
  const int16_t field = SEMAP_CANDUMP_FIELD_DATA;
  size_t p = 0;
  while (p < n) {
    if (s[p] == '.') {
      ++p;
      continue;
    }
    const int hi = hex_value(s[p]);
    if (hi < 0) return result(SEMAP_FB_BAD_FIELD, field);
    if (p + 1 == n) return result(SEMAP_FB_TRUNCATED, field); /* half a byte */
    const int lo = hex_value(s[p + 1]);
    if (lo < 0) return result(SEMAP_FB_BAD_FIELD, field);
    if (frame->len == max) return result(SEMAP_FB_TOO_LONG, field);
    frame->data[frame->len++] = (uint8_t)((hi << 4) | lo);
    p += 2;
  }
  return result(SEMAP_FB_OK, -1);
}

/* The frame token: ID#DATA, ID#R[len], ID##<flags>DATA, with an optional classic `_<dlc>`. */
static SemapFbResult parse_frame(const char* s, size_t n, SemapCandumpRecord* out) {
  size_t hash = 0;
  while (hash < n && s[hash] != '#') ++hash;
  uint32_t id = 0;
  for (size_t p = 0; p < hash; ++p) {
    const int v = hex_value(s[p]);
    if (v < 0 || p >= SEMAP_CANDUMP_EFF_DIGITS) {
      return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_ID);
    }
    id = (id << 4) | (uint32_t)v;
  }
  if (hash == n) return result(SEMAP_FB_TRUNCATED, SEMAP_CANDUMP_FIELD_ID);
  SemapCanFrame* f = &out->frame;
  if (hash == SEMAP_CANDUMP_SFF_DIGITS) {
    if (id > 0x7FFu) return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_ID);
    f->id = id;
  } else if (hash == SEMAP_CANDUMP_EFF_DIGITS) {
    if (id & SEMAP_CANDUMP_ERR_FLAG) {
      out->kind = SEMAP_CANDUMP_ERROR;
      id &= ~SEMAP_CANDUMP_ERR_FLAG;
    } else {
      f->extended = 1;
    }
    /* candump prints the EFF and RTR flags as the digit count and 'R', never in the id. */
    if (id > SEMAP_CANDUMP_EFF_MASK) return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_ID);
    f->id = id;
  } else {
    return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_ID);
  }

  size_t p = hash + 1;
  if (p < n && s[p] == '#') {
    if (out->kind == SEMAP_CANDUMP_ERROR) return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_ID);
    if (++p == n) return result(SEMAP_FB_TRUNCATED, SEMAP_CANDUMP_FIELD_FD_FLAGS);
    const int flags = hex_value(s[p++]);
    if (flags < 0) return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_FD_FLAGS);
    f->fd = 1;
    out->fd_flags = (uint8_t)flags;
    const SemapFbResult r = parse_data(s + p, n - p, SEMAP_CANFD_MAX_DLEN, f);
    if (r.status != SEMAP_FB_OK) return r;
    if (!is_fd_length(f->len)) return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_DATA);
    return result(SEMAP_FB_OK, -1);
  }
  if (p < n && (s[p] == 'R' || s[p] == 'r')) {
    if (out->kind == SEMAP_CANDUMP_ERROR)
      return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_DATA);
    out->kind = SEMAP_CANDUMP_REMOTE;
    if (++p == n) return result(SEMAP_FB_OK, -1);
    const int length = hex_value(s[p]);
    if (length < 0 || length > (int)SEMAP_CAN_MAX_DLEN || p + 1 != n) {
      return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_DATA);
    }
    f->len = (uint8_t)length;
    return result(SEMAP_FB_OK, -1);
  }
  /* A classic 8-byte frame may carry its raw DLC 9..15 as `_<hex>`: the payload is the same. */
  size_t end = n;
  if (n >= 2 && s[n - 2] == '_') {
    const int dlc = hex_value(s[n - 1]);
    if (dlc < 9) return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_DATA);
    end = n - 2;
  }
  const SemapFbResult r = parse_data(s + p, end - p, SEMAP_CAN_MAX_DLEN, f);
  if (r.status != SEMAP_FB_OK) return r;
  if (end != n && f->len != SEMAP_CAN_MAX_DLEN) {
    return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_DATA);
  }
  return result(SEMAP_FB_OK, -1);
}

SemapFbResult semap_candump_parse_line(const char* line, size_t len, SemapCandumpRecord* out) {
  memset(out, 0, sizeof *out);
  while (len > 0 && (is_blank(line[len - 1]) || line[len - 1] == '\r')) --len;
  if (len > SEMAP_CANDUMP_MAX_LINE) return result(SEMAP_FB_TOO_LONG, -1);
  size_t i = 0;
  SemapFbResult r = parse_timestamp(line, len, &i, out);
  if (r.status != SEMAP_FB_OK) return r;

  if (i == len) return result(SEMAP_FB_TRUNCATED, SEMAP_CANDUMP_FIELD_INTERFACE);
  if (!is_blank(line[i])) return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_TIMESTAMP);
  while (i < len && is_blank(line[i])) ++i;
  const size_t name_start = i;
  while (i < len && !is_blank(line[i])) ++i;
  const size_t name_len = i - name_start;
  if (name_len == 0) return result(SEMAP_FB_TRUNCATED, SEMAP_CANDUMP_FIELD_INTERFACE);
  if (i == len) return result(SEMAP_FB_TRUNCATED, SEMAP_CANDUMP_FIELD_ID);
  if (name_len > SEMAP_CANDUMP_MAX_INTERFACE) {
    return result(SEMAP_FB_TOO_LONG, SEMAP_CANDUMP_FIELD_INTERFACE);
  }
  for (size_t k = name_start; k < name_start + name_len; ++k) {
    if (line[k] < '!' || line[k] > '~')
      return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_INTERFACE);
  }
  memcpy(out->interface, line + name_start, name_len);
  out->interface[name_len] = '\0';

  while (i < len && is_blank(line[i])) ++i;
  const size_t frame_start = i;
  while (i < len && !is_blank(line[i])) ++i;
  r = parse_frame(line + frame_start, i - frame_start, out);
  if (r.status != SEMAP_FB_OK) return r;

  /* candump -x adds the direction: R (received), T (sent by this host), D (dropped). */
  while (i < len && is_blank(line[i])) ++i;
  if (i == len) return result(SEMAP_FB_OK, -1);
  if (i + 1 == len && (line[i] == 'R' || line[i] == 'T' || line[i] == 'D')) {
    return result(SEMAP_FB_OK, -1);
  }
  return result(SEMAP_FB_BAD_FIELD, SEMAP_CANDUMP_FIELD_TRAILER);
}

/* Appends `n` characters; returns 0 when they do not fit (leaving room for the NUL). */
static int append(char* out, size_t capacity, size_t* used, const char* s, size_t n) {
  if (*used + n >= capacity) return 0;
  memcpy(out + *used, s, n);
  *used += n;
  return 1;
}

size_t semap_candump_format_line(const SemapCandumpRecord* in, char* out, size_t capacity) {
  static const char kHex[] = "0123456789ABCDEF";
  const SemapCanFrame* f = &in->frame;
  size_t name_len = 0;
  while (name_len < sizeof in->interface && in->interface[name_len] != '\0') ++name_len;
  if (name_len == 0 || name_len > SEMAP_CANDUMP_MAX_INTERFACE) return 0;
  if (in->microseconds > 999999u) return 0;
  const int fd = in->kind == SEMAP_CANDUMP_DATA && f->fd;
  if (f->len > (fd ? SEMAP_CANFD_MAX_DLEN : SEMAP_CAN_MAX_DLEN)) return 0;
  if (fd && !is_fd_length(f->len)) return 0;

  char head[64];
  const int n = snprintf(head, sizeof head, "(%010llu.%06lu) ", (unsigned long long)in->seconds,
                         (unsigned long)in->microseconds);
  if (n < 0 || (size_t)n >= sizeof head) return 0;
  size_t used = 0;
  if (!append(out, capacity, &used, head, (size_t)n)) return 0;
  if (!append(out, capacity, &used, in->interface, name_len)) return 0;

  char id[SEMAP_CANDUMP_EFF_DIGITS + 2];
  size_t digits = SEMAP_CANDUMP_EFF_DIGITS;
  uint32_t value = f->id & SEMAP_CANDUMP_EFF_MASK;
  if (in->kind == SEMAP_CANDUMP_ERROR) {
    value = (f->id & SEMAP_CANDUMP_ERR_MASK) | SEMAP_CANDUMP_ERR_FLAG;
  } else if (!f->extended) {
    digits = SEMAP_CANDUMP_SFF_DIGITS;
    value = f->id & 0x7FFu;
  }
  id[0] = ' ';
  for (size_t d = 0; d < digits; ++d) id[1 + d] = kHex[(value >> (4u * (digits - 1u - d))) & 0xFu];
  if (!append(out, capacity, &used, id, digits + 1)) return 0;

  char body[2 + 1 + 2 * SEMAP_CANFD_MAX_DLEN + 2];
  size_t b = 0;
  body[b++] = '#';
  if (in->kind == SEMAP_CANDUMP_REMOTE) {
    body[b++] = 'R';
    if (f->len > 0) body[b++] = kHex[f->len];
  } else {
    if (fd) {
      body[b++] = '#';
      body[b++] = kHex[in->fd_flags & 0xFu];
    }
    for (uint8_t k = 0; k < f->len; ++k) {
      body[b++] = kHex[f->data[k] >> 4];
      body[b++] = kHex[f->data[k] & 0xFu];
    }
  }
  body[b++] = '\n';
  if (!append(out, capacity, &used, body, b)) return 0;
  out[used] = '\0';
  return used;
}

const char* semap_candump_field_name(int16_t field) {
  switch (field) {
    case SEMAP_CANDUMP_FIELD_TIMESTAMP:
      return "timestamp";
    case SEMAP_CANDUMP_FIELD_INTERFACE:
      return "interface";
    case SEMAP_CANDUMP_FIELD_ID:
      return "id";
    case SEMAP_CANDUMP_FIELD_FD_FLAGS:
      return "fd_flags";
    case SEMAP_CANDUMP_FIELD_DATA:
      return "data";
    case SEMAP_CANDUMP_FIELD_TRAILER:
      return "trailer";
    default:
      return "line";
  }
}
