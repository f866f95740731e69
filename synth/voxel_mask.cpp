#include "voxel_mask.h"

#include <algorithm>

namespace solidtex {

void VoxelBox::include(const Voxel& p) {
  if (empty()) {
    lo = p;
    hi = {p.x + 1, p.y + 1, p.z + 1};
    return;
  }
  lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
  hi = {std::max(hi.x, p.x + 1), std::max(hi.y, p.y + 1), std::max(hi.z, p.z + 1)};
}

VoxelMask::VoxelMask(const VoxelBox& box) : box_(box) {
  if (box.empty()) return;
  b0_ = {floor_div(box.lo.x, 8), floor_div(box.lo.y, 8), floor_div(box.lo.z, 8)};
  bn_ = {floor_div(box.hi.x - 1, 8) - b0_[0] + 1, floor_div(box.hi.y - 1, 8) - b0_[1] + 1,
         floor_div(box.hi.z - 1, 8) - b0_[2] + 1};
  table_.assign(size_t(bn_[0]) * bn_[1] * bn_[2], -1);
}

bool VoxelMask::insert(const Voxel& p) {
  const int b = brick_index(p);
  int32_t& slot = table_[size_t(b)];
  if (slot < 0) {
    slot = int32_t(bricks_.size());
    bricks_.push_back({});
  }
  const int bit = (p.x & 7) + 8 * (p.y & 7) + 64 * (p.z & 7);
  uint64_t& word = bricks_[size_t(slot)][size_t(bit >> 6)];
  const uint64_t m = uint64_t(1) << (bit & 63);
  if (word & m) return false;
  word |= m;
  ++count_;
  return true;
}

bool VoxelMask::contains(const Voxel& p) const {
  if (!box_.contains(p)) return false;
  const int32_t slot = table_[size_t(brick_index(p))];
  if (slot < 0) return false;
  const int bit = (p.x & 7) + 8 * (p.y & 7) + 64 * (p.z & 7);
  return (bricks_[size_t(slot)][size_t(bit >> 6)] >> (bit & 63)) & 1;
}

std::vector<Voxel> VoxelMask::to_vector() const {
  std::vector<Voxel> out;
  out.reserve(size_t(count_));
  for (int bz = 0; bz < bn_[2]; ++bz)
    for (int by = 0; by < bn_[1]; ++by)
      for (int bx = 0; bx < bn_[0]; ++bx) {
        const int32_t slot = table_[(size_t(bz) * bn_[1] + by) * bn_[0] + bx];
        if (slot < 0) continue;
        const auto& bits = bricks_[size_t(slot)];
        for (int w = 0; w < 8; ++w) {
          uint64_t word = bits[size_t(w)];
          while (word) {
            const int bit = w * 64 + __builtin_ctzll(word);
            word &= word - 1;
            out.push_back({(b0_[0] + bx) * 8 + (bit & 7), (b0_[1] + by) * 8 + ((bit >> 3) & 7),
                           (b0_[2] + bz) * 8 + (bit >> 6)});
          }
        }
      }
  return out;
}

}  // namespace solidtex
