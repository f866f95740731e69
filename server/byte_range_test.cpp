#include "byte_range.h"

#include <gtest/gtest.h>

namespace solidtex::server {
namespace {

void expect_range(std::string_view h, int64_t total, int64_t first, int64_t last) {
  const ByteRange r = parse_byte_range(h, total);
  EXPECT_EQ(r.kind, ByteRange::kSatisfiable) << h;
  EXPECT_EQ(r.first, first) << h;
  EXPECT_EQ(r.last, last) << h;
}

TEST(ByteRange, HonoursTheThreeSingleRangeForms) {
  expect_range("bytes=0-99", 1000, 0, 99);
  expect_range("bytes=10-10", 1000, 10, 10);
  expect_range("bytes=500-", 1000, 500, 999);
  expect_range("bytes=-100", 1000, 900, 999);
  expect_range("bytes=990-5000", 1000, 990, 999);  // a last position past the end is clipped
  expect_range("bytes=-5000", 1000, 0, 999);       // a suffix longer than the body is all of it
  expect_range("Bytes = 1-2 ", 1000, 1, 2);        // unit case-insensitive, optional whitespace
  expect_range("bytes=999-", 1000, 999, 999);
}

TEST(ByteRange, PastTheEndIsUnsatisfiable) {
  EXPECT_EQ(parse_byte_range("bytes=1000-", 1000).kind, ByteRange::kUnsatisfiable);
  EXPECT_EQ(parse_byte_range("bytes=1000-1001", 1000).kind, ByteRange::kUnsatisfiable);
  EXPECT_EQ(parse_byte_range("bytes=-0", 1000).kind, ByteRange::kUnsatisfiable);
  EXPECT_EQ(parse_byte_range("bytes=0-", 0).kind, ByteRange::kUnsatisfiable);
  EXPECT_EQ(parse_byte_range("bytes=-3", 0).kind, ByteRange::kUnsatisfiable);
}

TEST(ByteRange, IgnoresWhatItDoesNotServe) {
  for (const char* h : {"", "bytes", "bytes=", "bytes=-", "items=0-1", "bytes=a-b", "bytes=5-4", "bytes=0-1,3-4",
                        "bytes=1-2-3", "bytes=+1-2", "bytes=-+2", "bytes= -1 - 2", "bytes=99999999999999999999-",
                        "bytes=0x1-2", "bytesx=0-1"})
    EXPECT_EQ(parse_byte_range(h, 1000).kind, ByteRange::kIgnored) << h;
}

}  // namespace
}  // namespace solidtex::server
