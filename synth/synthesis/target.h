// What a request asks for: finest-level voxels, and how output samples map onto them.
// Axis cuts index finest voxels directly; plane cuts and points round world positions
// (world unit = finest voxel) to the nearest voxel with std::lround per axis.
#pragma once

#include <cstdint>
#include <vector>

#include "core/status.h"
#include "core/types.h"
#include "synthesis/voxel_mask.h"

namespace solidtex {

inline constexpr int64_t kMaxTargetSamples = int64_t(1) << 24;

struct TargetSet {
  std::vector<Voxel> voxels;        // distinct finest voxels, sorted
  std::vector<uint32_t> sample;     // output sample -> index into voxels
  int width = 0;                    // output shape: width*height samples (points: count x 1)
  int height = 0;
  VoxelBox bounds() const;

  // Pixel (i, j) of a cut: axis z -> (u0+i, v0+j, at); axis x -> (at, u0+i, v0+j);
  // axis y -> (u0+i, at, v0+j).
  static Result<TargetSet> axis_cut(char axis, int at, int u0, int v0, int width, int height);
  // Pixel (i, j) -> lround(origin + i*u + j*v), all in voxel units.
  static Result<TargetSet> plane_cut(const WorldPoint& origin, const WorldPoint& u, const WorldPoint& v, int width,
                                     int height);
  // Every voxel of the box [min, min+size), x fastest, then y, then z (height = size.y*size.z).
  static Result<TargetSet> box(const Voxel& min, int sx, int sy, int sz);
  static Result<TargetSet> points(const std::vector<WorldPoint>& points);
  static TargetSet from_voxels(const std::vector<Voxel>& samples, int width, int height);
};

}  // namespace solidtex
