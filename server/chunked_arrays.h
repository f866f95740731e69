// Volumes as chunked arrays (issue #14): the geometry, metadata and chunk bytes of the OME-Zarr
// 0.5 (Zarr v3), Zarr v2 / OME-Zarr 0.4 and Neuroglancer precomputed views of a volume, so that
// zarr-python, tensorstore, OME-Zarr readers and Neuroglancer open a volume by URL and each
// chunk is synthesized when first asked for.
//
// Datasets: scale s (dataset path "s") is synthesis level levels - 1 - s, so "0" is the finest
// and scale s has voxels 2^s finest voxels wide. Coarser datasets are the synthesis levels
// themselves (the output colors of their triples), not box filters of the finest.
// Window: the array shows the box [0, extent)^3 of finest voxels (volumes are unbounded); at
// scale s that is [0, ceil(extent / 2^s))^3. Arrays are [c, z, y, x] uint8 sRGB, chunks
// [3, 32, 32, 32], zstd-compressed, fill value 0; edge chunks are whole chunks of real voxels.
// Chunk bytes are exactly the region endpoint's voxels (same linear-to-sRGB quantisation),
// transposed from (z, y, x, c) to (c, z, y, x). Pure functions; thread-safe.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/status.h"
#include "core/types.h"

namespace solidtex::server {

constexpr int kArrayChunk = 32;  // voxels per chunk side, every scale

struct ArrayWindow {
  int scales = 1;          // datasets: the synthesis levels served, finest first
  int64_t extent = 1024;   // finest voxels per side, from the origin
  int64_t side(int scale) const { return (extent + (int64_t(1) << scale) - 1) >> scale; }
  int64_t chunks(int scale) const { return (side(scale) + kArrayChunk - 1) / kArrayChunk; }
};

// The OME-Zarr 0.5 group's zarr.json, with every array's metadata consolidated inline.
nlohmann::json ome_zarr_group(const ArrayWindow& w, const std::string& name);
// Dataset `scale`'s Zarr v3 zarr.json.
nlohmann::json zarr3_array(const ArrayWindow& w, int scale);
// Zarr v2: the group's .zgroup and .zattrs (OME-Zarr 0.4 multiscales), a dataset's .zarray.
nlohmann::json zarr2_group();
nlohmann::json ome_zarr04_attributes(const ArrayWindow& w, const std::string& name);
nlohmann::json zarr2_array(const ArrayWindow& w, int scale);

// The voxels (at that scale's level) of chunk (cz, cy, cx) of dataset `scale`: kNotFound
// outside the array (a scale or chunk index past the window), never for "not computed yet".
struct ChunkBox {
  Voxel min;
  std::array<int, 3> size{kArrayChunk, kArrayChunk, kArrayChunk};  // x, y, z
};
Result<ChunkBox> chunk_box(const ArrayWindow& w, int scale, const std::array<int64_t, 3>& czyx);

// Neuroglancer precomputed: the `info` (scale key s = dataset s, resolution 2^s, chunk sizes
// 32^3 and the flat 64x64x8 with its rotations so 2-D views do not pay for depth; `encoding`
// "raw" or "jpeg" for every scale), and the box a chunk name "x0-x1_y0-y1_z0-z1" names: inside
// the dataset, at most 64 a side and 32768 voxels, else kNotFound.
nlohmann::json precomputed_info(const ArrayWindow& w, const std::string& encoding);
Result<ChunkBox> precomputed_box(const ArrayWindow& w, int scale, const std::string& name);

// Chunk bytes in C order (c, z, y, x) (Neuroglancer raw: x fastest, channel slowest) from the
// sRGB8 samples of `voxels` voxels in target order (x fastest, then y, then z; three bytes each).
std::string chunk_bytes(const std::vector<uint8_t>& srgb_zyxc, int64_t voxels);
// zstd at level 3, one frame with its content size (what numcodecs' Zstd decodes).
Result<std::string> zstd_compress(const std::string& bytes);

}  // namespace solidtex::server
