// Voxel boxes, and the dense brick indexing shared by the request-local containers
// (VoxelMask, LevelStore): a box is covered by 8^3-voxel bricks aligned to multiples of 8,
// numbered x fastest, then y, then z. Brick numbers are dense in [0, size()), so a container
// maps them to its bricks with a plain table (no hashing), and iterating them in number order
// is a fixed order whatever the insertion order. Immutable after construction: thread-safe.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "core/types.h"

namespace solidtex {

// Half-open voxel box [lo, hi).
struct VoxelBox {
  Voxel lo{0, 0, 0};
  Voxel hi{0, 0, 0};
  bool empty() const { return hi.x <= lo.x || hi.y <= lo.y || hi.z <= lo.z; }
  bool contains(const Voxel& p) const {
    return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x < hi.x && p.y < hi.y && p.z < hi.z;
  }
  VoxelBox dilated(int r) const { return {{lo.x - r, lo.y - r, lo.z - r}, {hi.x + r, hi.y + r, hi.z + r}}; }
  void include(const Voxel& p);
  int64_t volume() const { return empty() ? 0 : int64_t(hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z); }
};

class BrickIndex {
 public:
  static constexpr int kSide = 8;
  static constexpr int kVoxels = kSide * kSide * kSide;

  BrickIndex() = default;
  explicit BrickIndex(const VoxelBox& box);

  // Bricks in the cover of the box (0 for an empty box).
  size_t size() const { return size_t(bn_[0]) * size_t(bn_[1]) * size_t(bn_[2]); }
  // Number of the brick holding p. p must lie in the cover (callers check the box first).
  size_t brick_of(const Voxel& p) const {
    return (size_t((p.z >> 3) - b0_[2]) * size_t(bn_[1]) + size_t((p.y >> 3) - b0_[1])) * size_t(bn_[0]) +
           size_t((p.x >> 3) - b0_[0]);  // >> floors negative values (C++20)
  }
  // Number of the brick (dx, dy, dz) bricks away from p's brick, or -1 outside the cover.
  int64_t brick_near(const Voxel& p, int dx, int dy, int dz) const {
    const int bx = (p.x >> 3) + dx - b0_[0], by = (p.y >> 3) + dy - b0_[1], bz = (p.z >> 3) + dz - b0_[2];
    if (bx < 0 || by < 0 || bz < 0 || bx >= bn_[0] || by >= bn_[1] || bz >= bn_[2]) return -1;
    return (int64_t(bz) * bn_[1] + by) * bn_[0] + bx;
  }
  // The lowest voxel of brick `index`.
  Voxel brick_origin(size_t index) const {
    const size_t bx = index % size_t(bn_[0]), rest = index / size_t(bn_[0]);
    const size_t by = rest % size_t(bn_[1]), bz = rest / size_t(bn_[1]);
    return {(b0_[0] + int(bx)) * kSide, (b0_[1] + int(by)) * kSide, (b0_[2] + int(bz)) * kSide};
  }
  // Brick coordinates (voxel / 8) of the cover's lowest brick, and the cover's extent in
  // bricks per axis; brick number = (z * extent[1] + y) * extent[0] + x, relative to first.
  const std::array<int, 3>& first_brick() const { return b0_; }
  const std::array<int, 3>& extent() const { return bn_; }
  // Position of p inside its brick, in [0, kVoxels): x fastest.
  static int voxel_in_brick(const Voxel& p) { return (p.x & 7) + 8 * (p.y & 7) + 64 * (p.z & 7); }
  // Inverse of voxel_in_brick for a brick's origin.
  static Voxel voxel_at(const Voxel& origin, int bit) {
    return {origin.x + (bit & 7), origin.y + ((bit >> 3) & 7), origin.z + (bit >> 6)};
  }

 private:
  std::array<int, 3> b0_{}, bn_{};
};

}  // namespace solidtex
