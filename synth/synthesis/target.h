// What a request asks for: finest-level voxels, and how output samples map onto them.
// Axis cuts and boxes index finest voxels directly. Plane cuts and points sample as told
// (voxel_sampling.h says which suits an exemplar): the voxel nearest the sample's world
// position (world unit = finest voxel; std::lround per axis), or the Catmull-Rom (tricubic,
// interpolating) combination of the 4x4x4 finest voxels around it, clamped to their range (no
// ringing). At integer positions the cubic weights are exactly (0, 1, 0, 0): either way a plane
// cut along the axes equals the axis cut, and a point on a voxel that voxel, bit for bit.
// Output colours are a pure function of the voxels' colours, hence of position.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/status.h"
#include "core/types.h"
#include "synthesis/voxel_sampling.h"
#include "synthesis/voxel_mask.h"

namespace solidtex {

inline constexpr int64_t kMaxTargetSamples = int64_t(1) << 24;
// Cubic-resampled plane cuts and points: at most this many samples (1024^2), and distinct voxels
// read (8 Mi: a unit-step 1024^2 oblique cut reads ~5 Mi, one with pixels 5 voxels apart 64 per
// pixel); more is kTooLarge naming "size" (cuts) or "points", found within a second or two.
inline constexpr int64_t kMaxResampledSamples = int64_t(1) << 20;
inline constexpr int64_t kMaxResampledVoxels = int64_t(1) << 23;

struct TargetSet {
  std::vector<Voxel> voxels;        // distinct finest voxels, sorted
  std::vector<uint32_t> sample;     // output sample -> index into voxels (its nearest voxel)
  // Resampled targets (plane cuts, points) only, else empty (`sample` is exact): sample s lies at
  // resample_floor[s] + resample_t[s] (t in [0, 1) per axis); its taps are the voxels
  // floor - 1 .. floor + 2 per axis that have a non-zero weight, all in `voxels`.
  std::vector<Voxel> resample_floor;
  std::vector<std::array<float, 3>> resample_t;
  int width = 0;                    // output shape: width*height samples (points: count x 1)
  int height = 0;
  VoxelBox bounds() const;
  // Output samples' colours from the colours of `voxels` (same order).
  std::vector<std::array<float, 3>> resolve(const std::vector<std::array<float, 3>>& voxel_rgb) const;

  // Pixel (i, j) of a cut: axis z -> (u0+i, v0+j, at); axis x -> (at, u0+i, v0+j);
  // axis y -> (u0+i, at, v0+j).
  static Result<TargetSet> axis_cut(char axis, int at, int u0, int v0, int width, int height);
  // Pixel (i, j) -> origin + i*u + j*v, all in voxel units, sampled as `sampling` says.
  static Result<TargetSet> plane_cut(const WorldPoint& origin, const WorldPoint& u, const WorldPoint& v, int width,
                                     int height, VoxelSampling sampling = VoxelSampling::kNearest);
  // The same with `resample` auto (nullopt) resolved: `preferred` (voxel_sampling.h), or
  // nearest where a cubic cut would pass the bounds above, so auto never refuses a cut nearest
  // takes. Given a sampling, exactly that one (and its errors).
  static Result<TargetSet> plane_cut(const WorldPoint& origin, const WorldPoint& u, const WorldPoint& v, int width,
                                     int height, std::optional<VoxelSampling> resample, VoxelSampling preferred);
  // How a plane cut or points target samples: kCubic when it resamples, else kNearest.
  VoxelSampling sampling() const { return resample_floor.empty() ? VoxelSampling::kNearest : VoxelSampling::kCubic; }
  // Every voxel of the box [min, min+size), x fastest, then y, then z (height = size.y*size.z).
  static Result<TargetSet> box(const Voxel& min, int sx, int sy, int sz);
  // Each point's nearest voxel, or its Catmull-Rom resampling (the same bounds as plane cuts,
  // errors naming "points"); the second form resolves auto like plane_cut's.
  static Result<TargetSet> points(const std::vector<WorldPoint>& points, VoxelSampling sampling = VoxelSampling::kNearest);
  static Result<TargetSet> points(const std::vector<WorldPoint>& points, std::optional<VoxelSampling> resample,
                                  VoxelSampling preferred);
  static TargetSet from_voxels(const std::vector<Voxel>& samples, int width, int height);
};

}  // namespace solidtex
