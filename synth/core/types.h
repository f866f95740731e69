// Strong coordinate types. Exemplar pixels, voxels, pyramid levels and world units never mix:
// each is its own type and conversions between them are explicit functions.
#pragma once

#include <array>
#include <compare>
#include <cstdint>

namespace solidtex {

// One of the three axis-aligned sectional planes of the local frame. Their axes are cyclic:
// XY = (x, y), YZ = (y, z), ZX = (z, x), so plane k's second axis is plane k+1's first axis.
enum class Plane : uint8_t { kXY = 0, kYZ = 1, kZX = 2 };
inline constexpr int kNumPlanes = 3;
inline constexpr Plane plane_from_index(int k) { return static_cast<Plane>(((k % 3) + 3) % 3); }
inline constexpr int index_of(Plane p) { return static_cast<int>(p); }
inline constexpr const char* plane_name(Plane p) {
  return p == Plane::kXY ? "xy" : p == Plane::kYZ ? "yz" : "zx";
}
// The 3D axes (0 = x, 1 = y, 2 = z) that plane k's exemplar x and y run along.
inline constexpr std::array<int, kNumPlanes> kPlaneFirstAxis = {0, 1, 2};
inline constexpr std::array<int, kNumPlanes> kPlaneSecondAxis = {1, 2, 0};

// Integer pixel position in an exemplar image (toroidal: any integer is valid and wraps).
struct ExemplarPixel {
  int32_t x = 0;
  int32_t y = 0;
  friend constexpr auto operator<=>(const ExemplarPixel&, const ExemplarPixel&) = default;
};

// A coordinate triple: one exemplar pixel per plane (Zhang §2, Dong et al. 2008).
struct CoordinateTriple {
  std::array<ExemplarPixel, kNumPlanes> at{};
  ExemplarPixel& operator[](Plane p) { return at[index_of(p)]; }
  const ExemplarPixel& operator[](Plane p) const { return at[index_of(p)]; }
  friend constexpr auto operator<=>(const CoordinateTriple&, const CoordinateTriple&) = default;
};

// Floor division for any sign of a (b > 0): -1 / 2 is -1, not 0.
inline constexpr int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// Pyramid level in synthesis order: 0 is the coarsest, levels-1 the finest.
struct PyramidLevel {
  int index = 0;
  friend constexpr auto operator<=>(const PyramidLevel&, const PyramidLevel&) = default;
};

// Exemplar-pixel spacing h of a level in a pyramid of `levels` levels (Zhang §4.2.1): the
// finest level samples every pixel (h = 1), each coarser one doubles it.
inline constexpr int stack_spacing(PyramidLevel level, int levels) {
  return 1 << (levels - 1 - level.index);
}

// Integer voxel on one pyramid level's lattice. Which level is carried alongside, not inside.
struct Voxel {
  int32_t x = 0;
  int32_t y = 0;
  int32_t z = 0;
  friend constexpr auto operator<=>(const Voxel&, const Voxel&) = default;
};

// A point in world units (by default one unit is one finest-level voxel).
struct WorldPoint {
  double x = 0;
  double y = 0;
  double z = 0;
};

}  // namespace solidtex
