#include "synthesis/level_store.h"

namespace solidtex {

LevelStore::LevelStore(const VoxelBox& box, int slots) : box_(box), slots_(slots) {
  if (box.empty()) return;
  b0_ = {floor_div(box.lo.x, 8), floor_div(box.lo.y, 8), floor_div(box.lo.z, 8)};
  bn_ = {floor_div(box.hi.x - 1, 8) - b0_[0] + 1, floor_div(box.hi.y - 1, 8) - b0_[1] + 1,
         floor_div(box.hi.z - 1, 8) - b0_[2] + 1};
  table_.assign(size_t(bn_[0]) * bn_[1] * bn_[2], nullptr);
}

void LevelStore::allocate(const Voxel& p) {
  Brick*& b = table_[size_t(brick_index(p))];
  if (b) return;
  auto nb = std::make_unique<Brick>();
  nb->states.resize(size_t(512) * slots_);
  nb->flags = std::make_unique<std::atomic<uint8_t>[]>(size_t(512) * slots_);
  for (size_t i = 0; i < size_t(512) * slots_; ++i) nb->flags[i].store(0, std::memory_order_relaxed);
  b = nb.get();
  bricks_.push_back(std::move(nb));
}

bool LevelStore::has(const Voxel& p) const { return box_.contains(p) && brick(p) != nullptr; }

uint8_t LevelStore::flags(const Voxel& p, int slot) const {
  if (!has(p)) return 0;
  return brick(p)->flags[index(p, slot)].load(std::memory_order_relaxed);
}

void LevelStore::set_flag(const Voxel& p, int slot, uint8_t f) {
  brick(p)->flags[index(p, slot)].fetch_or(f, std::memory_order_relaxed);
}

}  // namespace solidtex
