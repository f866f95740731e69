// Geometry, metadata and chunk bytes of the chunked-array views; the live service is tested by
// tests/python/test_arrays.py with zarr-python.
#include "chunked_arrays.h"

#include <gtest/gtest.h>
#include <zstd.h>

namespace solidtex::server {
namespace {

TEST(ChunkedArrays, DatasetsHalveAndChunksCoverTheWindow) {
  const ArrayWindow w{4, 1000 + 24};  // 1024
  EXPECT_EQ(w.side(0), 1024);
  EXPECT_EQ(w.side(3), 128);
  EXPECT_EQ(w.chunks(0), 32);
  EXPECT_EQ(ArrayWindow({2, 96}).side(1), 48);
  EXPECT_EQ(ArrayWindow({2, 96}).chunks(1), 2);  // 48 voxels: a whole chunk and an edge chunk
  const auto g = ome_zarr_group(w, "vol_x");
  const auto& ms = g["attributes"]["ome"]["multiscales"][0];
  ASSERT_EQ(ms["datasets"].size(), 4u);
  EXPECT_EQ(ms["datasets"][2]["coordinateTransformations"][0]["scale"], nlohmann::json({1.0, 4.0, 4.0, 4.0}));
  EXPECT_EQ(ms["datasets"][2]["coordinateTransformations"][1]["translation"], nlohmann::json({0.0, 1.5, 1.5, 1.5}));
  EXPECT_EQ(g["consolidated_metadata"]["metadata"]["3"], zarr3_array(w, 3));
  EXPECT_EQ(zarr3_array(w, 1)["shape"], nlohmann::json({3, 512, 512, 512}));
  EXPECT_EQ(zarr2_array(w, 1)["shape"], zarr3_array(w, 1)["shape"]);
  EXPECT_EQ(ome_zarr04_attributes(w, "v")["multiscales"][0]["version"], "0.4");
}

TEST(ChunkedArrays, ChunkBoxesAreInsideTheArrayOrNotFound) {
  const ArrayWindow w{3, 128};
  auto b = chunk_box(w, 0, {1, 2, 3});  // (cz, cy, cx)
  ASSERT_TRUE(b.is_ok());
  EXPECT_EQ(b->min, (Voxel{96, 64, 32}));
  EXPECT_TRUE(chunk_box(w, 2, {0, 0, 0}).is_ok());
  for (const auto& bad : {std::array<int64_t, 3>{4, 0, 0}, {0, -1, 0}, {0, 0, 1LL << 40}}) {
    auto r = chunk_box(w, 0, bad);
    ASSERT_FALSE(r.is_ok());
    EXPECT_EQ(r.status().code(), StatusCode::kNotFound);
  }
  EXPECT_EQ(chunk_box(w, 1, {2, 0, 0}).status().code(), StatusCode::kNotFound);  // 64 voxels: 2 chunks
  EXPECT_EQ(chunk_box(w, 3, {0, 0, 0}).status().field(), "scale");
}

TEST(ChunkedArrays, ChunkBytesAreChannelMajorAndZstdRoundTrips) {
  const int n = 2;
  std::vector<uint8_t> zyxc;
  for (int i = 0; i < n * n * n; ++i)
    for (int c = 0; c < 3; ++c) zyxc.push_back(uint8_t(10 * c + i));
  const std::string bytes = chunk_bytes(zyxc, n * n * n);
  ASSERT_EQ(bytes.size(), 24u);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 8; ++i) EXPECT_EQ(uint8_t(bytes[size_t(c * 8 + i)]), uint8_t(10 * c + i));
  const std::string z = zstd_compress(bytes).value();
  ASSERT_EQ(ZSTD_getFrameContentSize(z.data(), z.size()), 24u);  // numcodecs needs the content size
  std::string back(24, '\0');
  ASSERT_EQ(ZSTD_decompress(back.data(), back.size(), z.data(), z.size()), 24u);
  EXPECT_EQ(back, bytes);
}

TEST(ChunkedArrays, PrecomputedNamesBoxesInsideTheScaleOnly) {
  const ArrayWindow w{3, 128};
  const auto info = precomputed_info(w, "raw");
  ASSERT_EQ(info["scales"].size(), 3u);
  EXPECT_EQ(info["scales"][2]["encoding"], "raw");
  EXPECT_EQ(precomputed_info(w, "jpeg")["scales"][0]["encoding"], "jpeg");
  EXPECT_EQ(info["num_channels"], 3);
  EXPECT_EQ(info["scales"][1]["size"], nlohmann::json({64, 64, 64}));
  EXPECT_EQ(info["scales"][1]["resolution"], nlohmann::json({2, 2, 2}));
  auto b = precomputed_box(w, 0, "64-128_0-8_32-96");
  ASSERT_TRUE(b.is_ok()) << b.status().to_string();
  EXPECT_EQ(b->min, (Voxel{64, 0, 32}));
  EXPECT_EQ(b->size, (std::array<int, 3>{64, 8, 64}));
  EXPECT_TRUE(precomputed_box(w, 1, "32-64_32-64_32-64").is_ok());
  for (const char* bad : {"0-32_0-32_0-33x", "0-32_0-32", "32-0_0-8_0-8", "0-65_0-8_0-8", "0-64_0-64_0-64", "96-160_0-8_0-8",
                          "-8-0_0-8_0-8", "0-32_0-32_0-32 ", "a-b_c-d_e-f"})
    EXPECT_EQ(precomputed_box(w, 0, bad).status().code(), StatusCode::kNotFound) << bad;
  EXPECT_EQ(precomputed_box(w, 1, "64-96_0-32_0-32").status().code(), StatusCode::kNotFound);  // scale 1 is 64 wide
  EXPECT_EQ(precomputed_box(w, 3, "0-32_0-32_0-32").status().field(), "scale");
}

}  // namespace
}  // namespace solidtex::server
