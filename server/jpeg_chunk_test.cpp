#include "jpeg_chunk.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <jpeglib.h>

namespace solidtex::server {
namespace {

struct Decoded {
  int width = 0, height = 0, components = 0;
  std::vector<uint8_t> pixels;
};

// The test's own decoder (libjpeg's default error handler: a corrupt image ends the test binary).
Decoded decode(const std::string& jpeg) {
  jpeg_decompress_struct cinfo;
  jpeg_error_mgr err;
  cinfo.err = jpeg_std_error(&err);
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, reinterpret_cast<const unsigned char*>(jpeg.data()), jpeg.size());
  jpeg_read_header(&cinfo, TRUE);
  jpeg_start_decompress(&cinfo);
  Decoded d{int(cinfo.output_width), int(cinfo.output_height), int(cinfo.output_components), {}};
  d.pixels.resize(size_t(d.width) * d.height * d.components);
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = d.pixels.data() + size_t(cinfo.output_scanline) * d.width * d.components;
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return d;
}

// A texture-like chunk: smooth colour waves plus per-voxel detail, a different hue per z slice.
std::vector<uint8_t> chunk(int sx, int sy, int sz) {
  std::vector<uint8_t> v;
  for (int z = 0; z < sz; ++z)
    for (int y = 0; y < sy; ++y)
      for (int x = 0; x < sx; ++x) {
        v.push_back(uint8_t(128 + 100 * std::sin(0.3 * x + 0.1 * z)));
        v.push_back(uint8_t(40 + 6 * z + ((x * 7 + y * 13) % 5)));
        v.push_back(uint8_t(128 + 100 * std::cos(0.25 * y)));
      }
  return v;
}

TEST(JpegChunk, DecodesToTheVoxelsWithZSlicesStackedVertically) {
  const int sx = 32, sy = 16, sz = 24;
  const std::vector<uint8_t> voxels = chunk(sx, sy, sz);
  auto jpeg = jpeg_chunk(voxels, sx, sy, sz);
  ASSERT_TRUE(jpeg.is_ok()) << jpeg.status().message();
  const Decoded d = decode(*jpeg);
  ASSERT_EQ(d.width, sx);
  ASSERT_EQ(d.height, sy * sz);
  ASSERT_EQ(d.components, 3);
  ASSERT_EQ(d.pixels.size(), voxels.size());
  double sum = 0;
  int worst = 0;
  for (size_t i = 0; i < voxels.size(); ++i) {
    const int e = std::abs(int(d.pixels[i]) - int(voxels[i]));
    sum += e;
    worst = std::max(worst, e);
  }
  EXPECT_LT(sum / double(voxels.size()), 2.5);  // quality 90, 4:4:4
  EXPECT_LT(worst, 40);
  // Slice z's green level (40 + 6z) is where its rows are: row y of slice z is image row z*sy + y.
  for (int z = 0; z < sz; ++z) {
    double g = 0;
    for (int y = 0; y < sy; ++y)
      for (int x = 0; x < sx; ++x) g += d.pixels[(size_t(z * sy + y) * sx + x) * 3 + 1];
    EXPECT_NEAR(g / (sx * sy), 40 + 6 * z + 2, 2.0) << "slice " << z;
  }
  // Lower quality: fewer bytes.
  auto coarse = jpeg_chunk(voxels, sx, sy, sz, 30);
  ASSERT_TRUE(coarse.is_ok());
  EXPECT_LT(coarse->size(), jpeg->size());
}

TEST(JpegChunk, RefusesSizesThatDoNotMatchTheVoxels) {
  const std::vector<uint8_t> voxels = chunk(8, 8, 8);
  EXPECT_EQ(jpeg_chunk(voxels, 8, 8, 7).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(jpeg_chunk(voxels, 0, 8, 8).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(jpeg_chunk(std::vector<uint8_t>(size_t(3) * 65536, 0), 1, 65536, 1).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_TRUE(jpeg_chunk(voxels, 8, 8, 8).is_ok());
  EXPECT_TRUE(jpeg_chunk(std::vector<uint8_t>(3, 200), 1, 1, 1).is_ok());  // one voxel
}

}  // namespace
}  // namespace solidtex::server
