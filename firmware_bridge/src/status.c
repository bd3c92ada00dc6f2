#include "semap/firmware_bridge/status.h"

const char* semap_fb_status_name(SemapFbStatus status) {
  switch (status) {
    case SEMAP_FB_OK:
      return "ok";
    case SEMAP_FB_NEED_MORE:
      return "need_more";
    case SEMAP_FB_BAD_CHECKSUM:
      return "bad_checksum";
    case SEMAP_FB_TOO_LONG:
      return "too_long";
    case SEMAP_FB_TRUNCATED:
      return "truncated";
    case SEMAP_FB_UNKNOWN:
      return "unknown";
    case SEMAP_FB_BAD_FIELD:
      return "bad_field";
    case SEMAP_FB_STATUS_COUNT:
      break;
  }
  return "invalid_status";
}
