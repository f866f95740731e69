// Neuroglancer precomputed "jpeg" chunks: the chunk's voxels as one baseline JPEG of width
// x and height y * z (the z slices stacked top to bottom, each y rows of x pixels), three
// components (RGB, for num_channels 3). Encoded with libjpeg at full chroma resolution (4:4:4):
// textures have colour detail at the voxel scale that 4:2:0 would halve.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/status.h"

namespace solidtex::server {

constexpr int kJpegQuality = 90;

// `srgb_zyxc`: sx * sy * sz voxels, x fastest, then y, then z; three sRGB bytes each.
// kInvalidArgument for sizes that do not match or exceed JPEG's 65500 pixels a side.
Result<std::string> jpeg_chunk(const std::vector<uint8_t>& srgb_zyxc, int sx, int sy, int sz, int quality = kJpegQuality);

}  // namespace solidtex::server
