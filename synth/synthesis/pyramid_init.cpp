#include "synthesis/pyramid_init.h"

#include <cmath>

#include "core/hash.h"

namespace solidtex {
namespace {
std::array<const ImageF*, kNumPlanes> exemplar_planes(const Table& table) {
  const ExemplarSet& e = table.exemplars();
  return {&e.plane(Plane::kXY), &e.plane(Plane::kYZ), &e.plane(Plane::kZX)};
}

// The first (best by crossbar error) candidate triple of an xy pixel; the pixel itself in
// every plane when it has none.
CoordinateTriple first_candidate(const Table& table, ExemplarPixel pixel) {
  const auto list = table.level(PyramidLevel{0}).candidates->planes[0].at(pixel);
  if (!list.empty()) return list[0];
  CoordinateTriple t;
  t.at = {pixel, pixel, pixel};
  return t;
}

CoordinateTriple scatter_triple(const Table& table, const Voxel& v, uint32_t seed) {
  const ImageF& xy = table.exemplars().plane(Plane::kXY);
  const uint64_t hsh = hash_u64(uint64_t(int64_t(v.x)), uint64_t(int64_t(v.y)), uint64_t(int64_t(v.z)),
                                uint64_t(seed) << 32 ^ 0x5ca7ull);
  return first_candidate(table, {int(hsh % uint64_t(xy.width)), int((hsh >> 32) % uint64_t(xy.height))});
}
}  // namespace

std::array<int, 3> slab_subpart_sides(const Table& table, const SynthesisParams& params) {
  const int k = params.init_subpart, b = params.init_band;
  std::array<int, 3> sides{k, k, k};
  if (b == 0) return sides;
  const auto& w = table.params().suggested_plane_weights;  // (xy, yz, zx)
  if (w[1] >= w[2]) sides[0] = b;
  if (w[2] >= w[1]) sides[1] = b;
  return sides;
}

Init resolved_init(const Table& table, Init init) {
  if (init != Init::kAuto) return init;
  const ExemplarSet& e = table.exemplars();
  return e.shared() || e.crossed() ? Init::kScatter : Init::kSlab;
}

CoordinateTriple init_triple(const Table& table, const Voxel& v, const Rot3& r, const SynthesisParams& params) {
  if (resolved_init(table, params.init) == Init::kScatter) return scatter_triple(table, v, params.seed);
  const PyramidLevel coarsest{0};
  const int h = table.spacing(coarsest);
  const int n = table.params().neighborhood;
  const std::array<int, 3> k = slab_subpart_sides(table, params);
  const int sx = floor_div(v.x, k[0]), sy = floor_div(v.y, k[1]), sz = floor_div(v.z, k[2]);
  const int cx = sx * k[0] + k[0] / 2, cy = sy * k[1] + k[1] / 2, cz = sz * k[2] + k[2] / 2;
  const float rel[3] = {float(v.x - cx), float(v.y - cy), float(v.z - cz)};
  float local[3];
  r.apply_inverse(rel, local);
  const int wx = int(std::lround(local[0])) + cx, wy = int(std::lround(local[1])) + cy, wz = int(std::lround(local[2])) + cz;
  const int layer = floor_div(wz, n);
  const int dz = wz - layer * n - n / 2;
  const ImageF& xy = table.exemplars().plane(Plane::kXY);
  const uint64_t hsh = hash_u64(uint64_t(int64_t(layer)), uint64_t(int64_t(sx)) * 73856093ull ^ uint64_t(int64_t(sy)) * 19349663ull ^
                                    uint64_t(int64_t(sz)) * 83492791ull,
                                params.seed, 0x51ab);
  const int ox = int(hsh % uint64_t(xy.width)), oy = int((hsh >> 32) % uint64_t(xy.height));
  const ExemplarPixel pixel{ImageF::wrap(h * wx + ox, xy.width), ImageF::wrap(h * wy + oy, xy.height)};
  const CoordinateTriple base = first_candidate(table, pixel);
  const int step[3] = {0, 0, h * dz};
  return shift_triple(base, step, exemplar_planes(table));
}

CoordinateTriple upsample_triple(const Table& table, PyramidLevel child_level, const Voxel& v,
                                 const CoordinateTriple& parent, const Rot3& parent_rotation) {
  const float h = float(table.spacing(child_level));
  const float t[3] = {h * float(v.x & 1), h * float(v.y & 1), h * float(v.z & 1)};
  float local[3];
  parent_rotation.apply_inverse(t, local);
  const int step[3] = {int(std::lround(local[0])), int(std::lround(local[1])), int(std::lround(local[2]))};
  return shift_triple(parent, step, exemplar_planes(table));
}

}  // namespace solidtex
