#include "core/byte_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace solidtex {
namespace {

TEST(ByteIo, LittleEndianOnDiskRegardlessOfHost) {
  ByteWriter w;
  w.u32(0x01020304u);
  w.f32(1.0f);
  const auto& b = w.buffer();
  ASSERT_EQ(b.size(), 8u);
  EXPECT_EQ(b[0], 0x04);
  EXPECT_EQ(b[3], 0x01);
  EXPECT_EQ(b[7], 0x3f);  // 1.0f = 0x3f800000
  ByteReader r(b);
  uint32_t u = 0;
  float f = 0;
  ASSERT_TRUE(r.u32(u).is_ok());
  ASSERT_TRUE(r.f32(f).is_ok());
  EXPECT_EQ(u, 0x01020304u);
  EXPECT_EQ(f, 1.0f);
  uint8_t extra = 0;
  EXPECT_EQ(r.u8(extra).code(), StatusCode::kCorrupt);  // reading past the end
}

TEST(ByteIo, ChecksumSeesEveryByteAndLength) {
  std::vector<uint8_t> a(1001);
  for (size_t i = 0; i < a.size(); ++i) a[i] = uint8_t(i * 7);
  const uint64_t base = checksum64(a);
  for (size_t i : {size_t(0), size_t(500), size_t(1000)}) {
    auto b = a;
    b[i] ^= 1;
    EXPECT_NE(checksum64(b), base) << i;
  }
  auto c = a;
  c.push_back(0);
  EXPECT_NE(checksum64(c), base);
}

TEST(ByteIo, AtomicWriteReplacesAndLeavesNoTemporaries) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / "solidtex_byte_io_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "f.bin").string();
  std::vector<uint8_t> one{1, 2, 3}, two{4, 5};
  ASSERT_TRUE(write_file_atomic(path, one).is_ok());
  ASSERT_TRUE(write_file_atomic(path, two).is_ok());
  EXPECT_EQ(fs::file_size(path), 2u);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  EXPECT_EQ(write_file_atomic((dir / "missing" / "x").string(), one).code(), StatusCode::kIo);
}

}  // namespace
}  // namespace solidtex
