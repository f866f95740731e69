#include "synthesis/brick_index.h"

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

BrickIndex::BrickIndex(const VoxelBox& box) {
  if (box.empty()) return;
  b0_ = {floor_div(box.lo.x, kSide), floor_div(box.lo.y, kSide), floor_div(box.lo.z, kSide)};
  bn_ = {floor_div(box.hi.x - 1, kSide) - b0_[0] + 1, floor_div(box.hi.y - 1, kSide) - b0_[1] + 1,
         floor_div(box.hi.z - 1, kSide) - b0_[2] + 1};
}

}  // namespace solidtex
