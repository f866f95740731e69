#include "core/image_io.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

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
