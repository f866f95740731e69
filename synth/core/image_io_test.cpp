#include "core/image_io.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "testkit/test_support.h"

namespace solidtex {
namespace {

namespace fs = std::filesystem;

std::string tmp_path(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / "solidtex_image_io_test";
  fs::create_directories(dir);
  return (dir / name).string();
}

// Writes pixels (values in [0,1]) with OIIO in the format the extension names.
void write_with_oiio(const std::string& path, int w, int h, int c, OIIO::TypeDesc type) {
  std::vector<float> px(size_t(w) * h * c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) px[(size_t(y) * w + x) * c + k] = float((x * 7 + y * 13 + k * 29) % 97) / 96.f;
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(w, h, c, type);
  ASSERT_TRUE(out->open(path, spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
  out->close();
}

std::vector<uint8_t> file_bytes(const std::string& path) { return read_file_bytes(path, 1 << 30).value(); }

uint32_t crc32(const uint8_t* data, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; ++i) {
    c ^= data[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return ~c;
}

TEST(ImageIo, DecodesFormatsDepthsAndChannelCounts) {
  struct Case {
    const char* name;
    int channels;
    OIIO::TypeDesc type;
  };
  const Case cases[] = {{"rgb8.png", 3, OIIO::TypeDesc::UINT8},   {"gray8.png", 1, OIIO::TypeDesc::UINT8},
                        {"rgba8.png", 4, OIIO::TypeDesc::UINT8},  {"rgb16.png", 3, OIIO::TypeDesc::UINT16},
                        {"gray16.png", 1, OIIO::TypeDesc::UINT16}, {"rgb.jpg", 3, OIIO::TypeDesc::UINT8},
                        {"rgb16.tif", 3, OIIO::TypeDesc::UINT16}, {"rgbf.exr", 3, OIIO::TypeDesc::FLOAT},
                        {"rgbaf.exr", 4, OIIO::TypeDesc::HALF}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = tmp_path(c.name);
    write_with_oiio(path, 40, 24, c.channels, c.type);  // non-square
    auto img = load_image(path);
    ASSERT_TRUE(img.is_ok()) << img.status().to_string();
    EXPECT_EQ(img->width, 40);
    EXPECT_EQ(img->height, 24);
    EXPECT_EQ(img->channels, 3);
    // Same result from memory as from the path.
    auto mem = decode_image(file_bytes(path));
    ASSERT_TRUE(mem.is_ok());
    EXPECT_EQ(mem->pixels, img->pixels);
    if (c.channels <= 2) {  // gray replicated
      for (int64_t i = 0; i < img->pixel_count(); ++i) {
        EXPECT_EQ(img->pixels[i * 3], img->pixels[i * 3 + 1]);
        EXPECT_EQ(img->pixels[i * 3], img->pixels[i * 3 + 2]);
      }
    }
  }
}

TEST(ImageIo, IntegerImagesAreLinearisedFromSrgbFloatImagesAreNot) {
  const std::string png = tmp_path("lin.png"), exr = tmp_path("lin.exr");
  write_with_oiio(png, 16, 16, 3, OIIO::TypeDesc::UINT8);
  write_with_oiio(exr, 16, 16, 3, OIIO::TypeDesc::FLOAT);
  auto a = load_image(png).value(), b = load_image(exr).value();
  // Pixel (3,0) channel 0 holds 21/96 in both files.
  EXPECT_NEAR(b.at(3, 0)[0], 21.f / 96.f, 1e-6);
  EXPECT_NEAR(a.at(3, 0)[0], srgb_to_linear(std::round(21.f / 96.f * 255.f) / 255.f), 1e-6);
}

TEST(ImageIo, PngEncodingRoundTrips) {
  ImageF img = testing::procedural(ProceduralKind::kBricks, 33, 17);
  auto bytes = encode_png_srgb8(img);
  ASSERT_TRUE(bytes.is_ok());
  auto back = decode_image(*bytes).value();
  ASSERT_EQ(back.width, 33);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    EXPECT_NEAR(linear_to_srgb(back.pixels[i]), linear_to_srgb(img.pixels[i]), 0.5f / 255.f + 1e-4f);
}

TEST(ImageIo, RejectsEmptyGarbageAndTruncated) {
  auto empty = decode_image({});
  EXPECT_EQ(empty.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(empty.status().message().find("empty"), std::string::npos);

  std::vector<uint8_t> garbage(500, 0x42);
  EXPECT_EQ(decode_image(garbage).status().code(), StatusCode::kUnsupported);

  const std::string png = tmp_path("trunc.png");
  write_with_oiio(png, 64, 64, 3, OIIO::TypeDesc::UINT8);
  std::vector<uint8_t> bytes = file_bytes(png);
  std::vector<uint8_t> truncated(bytes.begin(), bytes.begin() + bytes.size() / 2);
  auto t = decode_image(truncated);
  EXPECT_FALSE(t.is_ok());
  EXPECT_EQ(t.status().code(), StatusCode::kCorrupt) << t.status().to_string();

  std::vector<uint8_t> corrupt = bytes;  // valid signature, scrambled body
  for (size_t i = 16; i < corrupt.size(); ++i) corrupt[i] ^= uint8_t(i * 31);
  auto c = decode_image(corrupt);
  EXPECT_FALSE(c.is_ok());

  const std::string jpg = tmp_path("trunc.jpg");
  write_with_oiio(jpg, 64, 64, 3, OIIO::TypeDesc::UINT8);
  std::vector<uint8_t> jb = file_bytes(jpg);
  jb.resize(jb.size() / 2);
  EXPECT_FALSE(decode_image(jb).is_ok());

  EXPECT_EQ(load_image(tmp_path("does-not-exist.png")).status().code(), StatusCode::kNotFound);
}

TEST(ImageIo, RefusesPngsWhoseChunksEndEarly) {
  const std::string path = tmp_path("chunks.png");
  write_with_oiio(path, 16, 16, 3, OIIO::TypeDesc::UINT8);
  const std::vector<uint8_t> png = file_bytes(path);
  ASSERT_TRUE(decode_image(png).is_ok());
  // Cut inside the last chunk (IEND), at a chunk boundary (no IEND), after the signature.
  for (size_t keep : {png.size() - 1, png.size() - 12, size_t(8), size_t(20)}) {
    std::vector<uint8_t> cut(png.begin(), png.begin() + keep);
    auto r = decode_image(cut);
    EXPECT_EQ(r.status().code(), StatusCode::kCorrupt) << keep;
    EXPECT_NE(r.status().message().find("truncated PNG"), std::string::npos) << r.status().message();
  }
  // A chunk length beyond the PNG limit of 2^31 - 1.
  std::vector<uint8_t> huge = png;
  huge[8] = 0x80;
  EXPECT_NE(decode_image(huge).status().message().find("chunk length"), std::string::npos);
  // Bytes after IEND are not looked at.
  std::vector<uint8_t> tail = png;
  tail.insert(tail.end(), {1, 2, 3});
  EXPECT_TRUE(decode_image(tail).is_ok());
}

// OpenEXR 3.1's classic reader takes a zip chunk that inflates to fewer bytes than its scanlines
// need and returns the rest of its buffer (uninitialised heap memory) as pixels, with no
// error; decode_image reads EXR with the OpenEXR Core library, which refuses the chunk.
TEST(ImageIo, RefusesExrChunkThatInflatesShort) {
  const std::string path = tmp_path("short_chunk.exr");
  {
    std::vector<float> px(8 * 12 * 3, 0.5f);
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(8, 12, 3, OIIO::TypeDesc::HALF);
    spec.attribute("compression", "zip");  // 16 scanlines per chunk: one chunk
    ASSERT_TRUE(out->open(path, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
    out->close();
  }
  std::vector<uint8_t> exr = file_bytes(path);
  ASSERT_TRUE(decode_image(exr).is_ok());
  // Skip the magic and version, then the attributes (name\0 type\0 i32 size, data) up to the
  // header's closing \0: the one-entry offset table follows, then the chunk (i32 y, i32 size).
  size_t at = 8;
  while (exr.at(at) != 0) {
    at = size_t(std::find(exr.begin() + long(at), exr.end(), 0) - exr.begin()) + 1;  // name
    at = size_t(std::find(exr.begin() + long(at), exr.end(), 0) - exr.begin()) + 1;  // type
    int32_t size = 0;
    std::memcpy(&size, &exr.at(at), 4);
    at += 4 + size_t(size);
  }
  uint64_t chunk = 0;
  std::memcpy(&chunk, &exr.at(at + 1), 8);
  {
    // An attribute that claims more bytes than the file has is refused before OpenEXR
    // allocates them (the Core library allocates the declared size first).
    std::vector<uint8_t> big = exr;
    size_t size_at = 8;
    for (int k = 0; k < 2; ++k) size_at = size_t(std::find(big.begin() + long(size_at), big.end(), 0) - big.begin()) + 1;
    const uint32_t claim = 0x7fffff00u;
    std::memcpy(&big[size_at], &claim, 4);
    auto r = decode_image(big);
    EXPECT_EQ(r.status().code(), StatusCode::kCorrupt);
    EXPECT_NE(r.status().message().find("claims 2147483392 bytes"), std::string::npos) << r.status().to_string();
  }
  ASSERT_LT(chunk + 8, exr.size());
  {
    // A data window of 8 x 100000000 pixels is too large before OpenEXR allocates its chunk
    // table (one entry per 16 of those lines).
    std::vector<uint8_t> tall = exr;
    const std::string key("dataWindow\0box2i\0", 17);
    const auto it = std::search(tall.begin(), tall.end(), key.begin(), key.end());
    ASSERT_NE(it, tall.end());
    const size_t value = size_t(it - tall.begin()) + key.size() + 4;  // after the i32 size
    const int32_t ymax = 99999999;
    std::memcpy(&tall[value + 12], &ymax, 4);
    auto r = decode_image(tall);
    EXPECT_EQ(r.status().code(), StatusCode::kTooLarge) << r.status().to_string();
    EXPECT_NE(r.status().message().find("8x100000000"), std::string::npos) << r.status().to_string();
  }
  {
    // A chunk table entry of -8: OIIO's IOMemReader read the 8 bytes before the buffer (a
    // heap-buffer-overflow under ASan, make test-sanitize); decode_image's reader reads nothing.
    std::vector<uint8_t> before = exr;
    const int64_t minus8 = -8;
    std::memcpy(&before[at + 1], &minus8, 8);
    auto r = decode_image(before);
    ASSERT_FALSE(r.is_ok()) << "decoded";
    EXPECT_EQ(r.status().code(), StatusCode::kCorrupt) << r.status().to_string();
  }
  // zlib's deflate of 10 zero bytes, where the chunk needs 8 x 12 x 3 halves (576 bytes).
  const std::vector<uint8_t> short_zlib = {0x78, 0x9c, 0x63, 0x60, 0x80, 0x01, 0x00, 0x00, 0x0a, 0x00, 0x01};
  exr.resize(chunk + 4);
  const int32_t size = int32_t(short_zlib.size());
  exr.insert(exr.end(), reinterpret_cast<const uint8_t*>(&size), reinterpret_cast<const uint8_t*>(&size) + 4);
  exr.insert(exr.end(), short_zlib.begin(), short_zlib.end());
  auto r = decode_image(exr);
  ASSERT_FALSE(r.is_ok()) << "decoded";
  EXPECT_EQ(r.status().code(), StatusCode::kCorrupt) << r.status().to_string();
  // Refused by the reader, not (by chance) because the garbage held a non-finite value.
  EXPECT_NE(r.status().message().find("pixel data cannot be decoded"), std::string::npos) << r.status().to_string();
}

TEST(ImageIo, RejectsAbsurdHeaderBeforeDecoding) {
  // A PNG whose IHDR (with a valid CRC) claims 100000 x 100000 pixels and has no data.
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  auto be32 = [&](uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) png.push_back(uint8_t(v >> s));
  };
  be32(13);
  const size_t chunk = png.size();
  for (char ch : std::string("IHDR")) png.push_back(uint8_t(ch));
  be32(100000);
  be32(100000);
  png.insert(png.end(), {8, 2, 0, 0, 0});
  be32(crc32(&png[chunk], png.size() - chunk));
  for (const char* name : {"IDAT", "IEND"}) {  // empty data and end chunks, valid CRCs
    be32(0);
    const size_t at = png.size();
    for (int i = 0; i < 4; ++i) png.push_back(uint8_t(name[i]));
    be32(crc32(&png[at], 4));
  }
  auto r = decode_image(png);
  ASSERT_FALSE(r.is_ok());
  EXPECT_EQ(r.status().code(), StatusCode::kTooLarge) << r.status().to_string();
  EXPECT_NE(r.status().message().find("100000x100000"), std::string::npos) << r.status().message();

  ImageLimits tight;
  tight.max_bytes = 100;
  const std::string small = tmp_path("small.png");
  write_with_oiio(small, 32, 32, 3, OIIO::TypeDesc::UINT8);
  EXPECT_EQ(load_image(small, tight).status().code(), StatusCode::kTooLarge);
}

}  // namespace
}  // namespace solidtex
