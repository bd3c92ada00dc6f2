#include "semap/firmware_bridge/candump_log.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <sstream>
#include <string>

#include "semap/firmware_bridge/candump_reader.hpp"

namespace semap::firmware_bridge {
namespace {

SemapFbResult parse(const std::string& line, SemapCandumpRecord& out) {
  return semap_candump_parse_line(line.data(), line.size(), &out);
}

TEST(CandumpLog, ParsesTheLineKindsCandumpWrites) {
  SemapCandumpRecord r;
  ASSERT_EQ(parse("(1700000000.012345) can0 123#DEADBEEF", r).status, SEMAP_FB_OK);
  EXPECT_EQ(r.seconds, 1700000000u);
  EXPECT_EQ(r.microseconds, 12345u);
  EXPECT_STREQ(r.interface, "can0");
  EXPECT_EQ(r.kind, SEMAP_CANDUMP_DATA);
  EXPECT_EQ(r.frame.id, 0x123u);
  EXPECT_EQ(r.frame.extended, 0);
  ASSERT_EQ(r.frame.len, 4);
  EXPECT_EQ(r.frame.data[0], 0xDE);
  EXPECT_EQ(r.frame.data[3], 0xEF);

  // 29-bit id (J1939 ARI, priority 3, source 0x80), lower-case hex and '.' separators.
  ASSERT_EQ(parse("(0000000001.000000) vcan0 0cf02a80#00.7d.80.7d.00.00.24.04", r).status,
            SEMAP_FB_OK);
  EXPECT_EQ(r.frame.extended, 1);
  EXPECT_EQ(r.frame.id, 0x0CF02A80u);
  EXPECT_EQ(r.frame.len, 8);
  EXPECT_EQ(r.frame.data[7], 0x04);

  ASSERT_EQ(parse("(1.000001) can1 12345678##3112233", r).status, SEMAP_FB_OK);
  EXPECT_EQ(r.frame.fd, 1);
  EXPECT_EQ(r.fd_flags, 3);
  EXPECT_EQ(r.frame.len, 3);

  ASSERT_EQ(parse("(1.000001) can0 7FF#R5", r).status, SEMAP_FB_OK);
  EXPECT_EQ(r.kind, SEMAP_CANDUMP_REMOTE);
  EXPECT_EQ(r.frame.len, 5);

  // Error frame: CAN_ERR_FLAG | CAN_ERR_BUSOFF, as `candump -e -L` logs it.
  ASSERT_EQ(parse("(1.000001) can0 20000040#0000000000000000", r).status, SEMAP_FB_OK);
  EXPECT_EQ(r.kind, SEMAP_CANDUMP_ERROR);
  EXPECT_EQ(r.frame.id, 0x40u);
  EXPECT_EQ(r.frame.len, 8);

  // candump -x direction, a raw DLC beyond 8 on a classic frame, CRLF line ends.
  EXPECT_EQ(parse("(1.000001) can0 123#11 T", r).status, SEMAP_FB_OK);
  EXPECT_EQ(parse("(1.000001) can0 123#1122334455667788_C", r).status, SEMAP_FB_OK);
  EXPECT_EQ(parse("(1.000001) can0 123#\r", r).status, SEMAP_FB_OK);
  EXPECT_EQ(r.frame.len, 0);
}

struct Damage {
  const char* line;
  SemapFbStatus status;
  const char* field;
};

TEST(CandumpLog, DamageNamesTheField) {
  const Damage cases[] = {
      {"(1700000000.0123", SEMAP_FB_TRUNCATED, "timestamp"},
      {"1700000000.012345) can0 123#11", SEMAP_FB_BAD_FIELD, "timestamp"},
      {"(1700000000.01234) can0 123#11", SEMAP_FB_BAD_FIELD, "timestamp"},
      {"(1700000000.012345)", SEMAP_FB_TRUNCATED, "interface"},
      {"(1700000000.012345) can0", SEMAP_FB_TRUNCATED, "id"},
      {"(1700000000.012345) can0 12", SEMAP_FB_TRUNCATED, "id"},
      {"(1700000000.012345) a_very_long_interface 123#11", SEMAP_FB_TOO_LONG, "interface"},
      {"(1700000000.012345) ca\x01n 123#11", SEMAP_FB_BAD_FIELD, "interface"},
      {"(1700000000.012345) can0 1234#11", SEMAP_FB_BAD_FIELD, "id"},
      {"(1700000000.012345) can0 800#11", SEMAP_FB_BAD_FIELD, "id"},
      {"(1700000000.012345) can0 1G3#11", SEMAP_FB_BAD_FIELD, "id"},
      {"(1700000000.012345) can0 40000000#11", SEMAP_FB_BAD_FIELD, "id"},
      {"(1700000000.012345) can0 123#112", SEMAP_FB_TRUNCATED, "data"},
      {"(1700000000.012345) can0 123#11X2", SEMAP_FB_BAD_FIELD, "data"},
      {"(1700000000.012345) can0 123#112233445566778899", SEMAP_FB_TOO_LONG, "data"},
      {"(1700000000.012345) can0 123##", SEMAP_FB_TRUNCATED, "fd_flags"},
      {"(1700000000.012345) can0 123##0112233445566778899", SEMAP_FB_BAD_FIELD, "data"},
      {"(1700000000.012345) can0 123#R9", SEMAP_FB_BAD_FIELD, "data"},
      {"(1700000000.012345) can0 123#11 X", SEMAP_FB_BAD_FIELD, "trailer"},
      {"(1700000000.012345) can0 123#11 T T", SEMAP_FB_BAD_FIELD, "trailer"},
  };
  for (const Damage& d : cases) {
    SCOPED_TRACE(d.line);
    SemapCandumpRecord r;
    const SemapFbResult res = parse(d.line, r);
    EXPECT_EQ(res.status, d.status) << semap_fb_status_name(res.status);
    EXPECT_STREQ(semap_candump_field_name(res.field), d.field);
  }
}

TEST(CandumpLog, FormatsAsCandumpDoes) {
  SemapCandumpRecord r{};
  r.seconds = 1700000000;
  r.microseconds = 42;
  std::strcpy(r.interface, "can0");
  r.frame.id = 0x0CF02A80u;
  r.frame.extended = 1;
  r.frame.len = 2;
  r.frame.data[0] = 0xAB;
  r.frame.data[1] = 0x01;
  EXPECT_EQ(format_candump_line(r), "(1700000000.000042) can0 0CF02A80#AB01\n");
  r.frame.extended = 0;
  r.frame.id = 0x12;
  EXPECT_EQ(format_candump_line(r), "(1700000000.000042) can0 012#AB01\n");
  r.kind = SEMAP_CANDUMP_REMOTE;
  EXPECT_EQ(format_candump_line(r), "(1700000000.000042) can0 012#R2\n");
  r.kind = SEMAP_CANDUMP_ERROR;
  r.frame.id = 0x04;  // CAN_ERR_CRTL
  EXPECT_EQ(format_candump_line(r), "(1700000000.000042) can0 20000004#AB01\n");
  r.kind = SEMAP_CANDUMP_DATA;
  r.frame.id = 0x12;
  r.frame.fd = 1;
  r.fd_flags = 1;
  EXPECT_EQ(format_candump_line(r), "(1700000000.000042) can0 012##1AB01\n");
  r.frame.len = 9;  // not a CAN FD length
  char small[16];
  EXPECT_EQ(semap_candump_format_line(&r, small, sizeof small), 0u);
  EXPECT_THROW(format_candump_line(r), std::invalid_argument);
}

TEST(CandumpLog, RandomRecordsRoundTrip) {
  std::mt19937 rng(7);
  const std::uint8_t fd_lengths[] = {0, 1, 5, 8, 12, 16, 20, 24, 32, 48, 64};
  for (int n = 0; n < 2000; ++n) {
    SemapCandumpRecord in{};
    in.seconds = rng() % 4000000000u;
    in.microseconds = rng() % 1000000u;
    std::snprintf(in.interface, sizeof in.interface, "can%u", static_cast<unsigned>(rng() % 100));
    in.kind = static_cast<std::uint8_t>(rng() % 3);
    in.frame.extended = in.kind == SEMAP_CANDUMP_ERROR ? 0 : rng() % 2;
    in.frame.id = in.kind == SEMAP_CANDUMP_ERROR ? rng() % 0x400u
                  : in.frame.extended            ? rng() & 0x1FFFFFFFu
                                                 : rng() & 0x7FFu;
    in.frame.fd = in.kind == SEMAP_CANDUMP_DATA ? rng() % 2 : 0;
    in.fd_flags = in.frame.fd ? rng() % 16 : 0;
    in.frame.len = in.frame.fd ? fd_lengths[rng() % std::size(fd_lengths)] : rng() % 9;
    if (in.kind != SEMAP_CANDUMP_REMOTE) {
      for (int k = 0; k < in.frame.len; ++k) in.frame.data[k] = static_cast<std::uint8_t>(rng());
    }
    const std::string line = format_candump_line(in);
    ASSERT_EQ(line.back(), '\n');
    SemapCandumpRecord out;
    ASSERT_EQ(parse(line.substr(0, line.size() - 1), out).status, SEMAP_FB_OK) << line;
    EXPECT_EQ(std::memcmp(&in, &out, sizeof in), 0) << line;
  }
}

TEST(CandumpReader, DecodesUpToTheDamageAndNamesTheLine) {
  std::istringstream log(
      "(1.000000) can0 123#01\n"
      "\n"
      "(1.000100) can0 124#02\n"
      "(1.000200) can0 125#0X\n"
      "(1.000300) can0 126#04\n");
  CandumpReader reader(log, "drive.log");
  auto a = reader.next();
  auto b = reader.next();
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->frame.id, 0x123u);
  EXPECT_EQ(b->frame.id, 0x124u);
  EXPECT_FALSE(reader.next());
  EXPECT_EQ(reader.error(), "drive.log:4: data: bad_field in '(1.000200) can0 125#0X'");
  EXPECT_FALSE(reader.next());  // stays stopped at the damage
}

TEST(CandumpReader, ALastLineWithoutNewlineIsTruncation) {
  std::istringstream cut("(1.000000) can0 123#0102\n(1.000100) can0 123#01");
  CandumpReader reader(cut, "cut.log");
  EXPECT_TRUE(reader.next());
  EXPECT_FALSE(reader.next());
  EXPECT_NE(reader.error().find("cut.log:2: line: truncated"), std::string::npos) << reader.error();

  std::istringstream intact("(1.000000) can0 123#0102\n");
  CandumpReader whole(intact, "ok.log");
  EXPECT_TRUE(whole.next());
  EXPECT_FALSE(whole.next());
  EXPECT_EQ(whole.error(), "");

  std::istringstream endless(std::string(100000, 'A'));
  CandumpReader garbage(endless, "garbage.log");
  EXPECT_FALSE(garbage.next());
  EXPECT_NE(garbage.error().find("garbage.log:1: line: too_long"), std::string::npos);
}

}  // namespace
}  // namespace semap::firmware_bridge
