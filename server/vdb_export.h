// Encodes a box of voxel colors as an OpenVDB file in memory: one Vec3s grid named "color"
// (linear RGB), index space = finest voxels (unit voxel size, so world = index). The only
// server translation unit that includes OpenVDB.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/status.h"
#include "core/types.h"

namespace solidtex::server {

// `rgb` holds size[0]*size[1]*size[2] colors, x fastest, then y, then z.
Result<std::string> encode_vdb_box(const Voxel& min, std::array<int, 3> size,
                                   const std::vector<std::array<float, 3>>& rgb, const std::string& volume_id);

}  // namespace solidtex::server
